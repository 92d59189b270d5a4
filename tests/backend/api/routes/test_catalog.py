"""The catalog route (backend/api/routes/catalog.py): the registered controllers, for choosers."""

from backend.jobs import KINDS
from sim_core.control.registry import LAWS


def test_the_catalog_lists_every_registered_controller_in_order(client):
    response = client.get("/api/v1/catalog")
    assert response.status_code == 200
    controllers = response.json()["controllers"]
    assert [entry["name"] for entry in controllers] == list(LAWS)
    assert all(entry["summary"] == LAWS[entry["name"]].summary for entry in controllers)
    assert [entry["sets_leg_angle"] for entry in controllers] == [law.sets_leg_angle for law in LAWS.values()]


def test_the_catalog_lists_every_job_kind_with_its_request_schema(client):
    catalog = client.get("/api/v1/catalog").json()
    schemas = client.get("/openapi.json").json()["components"]["schemas"]
    assert [entry["name"] for entry in catalog["job_kinds"]] == [kind.name for kind in KINDS]
    for entry in catalog["job_kinds"]:
        request = schemas[entry["request"]]  # the panel reads fields and ranges there
        assert request["properties"]["kind"].get("const", request["properties"]["kind"].get("default")) == entry["name"]
        assert entry["title"]
