"""Worlds through the API (backend/api/routes/worlds.py): stored as posted and read back to the last
digit, made from a named world or a seed, renamed, deleted unless in use (a 409 naming the user),
every mistake a 422 naming the side and point or segment, every change behind the token."""

import json
import math

import pytest

from sim_core.model.controls import ControlSchedule
from sim_core.model.presets import get_preset
from sim_core.world.climb import climb_world
from sim_core.world.files import world_from_document, world_to_document
from sim_core.world.named import NAMED_WORLDS
from sim_core.world.random_world import random_world
from tests.backend.api.bodies import RUN

# Coordinates with every digit a double has, friction as a number, the model's (null) and no slip.
POSTED = {
    "name": "lab wall 3",
    "units": "l0",
    "left": {"points": [[-1.21, 0.0], [-1.1234567890123457, 0.7071067811865476], [-1.21, 3.0]],
             "mu": [0.35, None]},
    "right": {"points": [[1.21, 0.0], [1.21, 1e-3], [1.3333333333333333, 2.5]], "mu": ["inf", 1.5]},
}  # fmt: skip


def _post(client, auth, name, **source):
    return client.post("/api/v1/worlds", json={"name": name} | source, headers=auth)


def test_a_world_comes_back_as_posted_and_is_renamed_listed_and_deleted(client, auth):
    created = _post(client, auth, "wall 3", world=POSTED)
    assert created.status_code == 201, created.text
    world = created.json()
    assert world["world"] == POSTED and json.dumps(world["world"]) == json.dumps(POSTED)
    assert (world["source"], world["runs"], world["jobs"]) == ("posted", 0, 0)
    read = client.get(f"/api/v1/worlds/{world['id']}").json()
    assert read["world"] == POSTED and read["name"] == "wall 3" and read["created_by"]
    renamed = client.patch(f"/api/v1/worlds/{world['id']}", json={"name": "wall 3b"}, headers=auth).json()
    assert renamed["name"] == "wall 3b" and renamed["world"] == POSTED
    page = client.get("/api/v1/worlds").json()
    assert page["total"] == 1 and [item["name"] for item in page["items"]] == ["wall 3b"]
    assert client.delete(f"/api/v1/worlds/{world['id']}", headers=auth).status_code == 204
    assert client.get(f"/api/v1/worlds/{world['id']}").status_code == 404


def test_a_named_world_and_a_random_one_are_stored_as_their_files(client, auth):
    staircase = _post(client, auth, "stairs", named="staircase").json()
    assert staircase["source"] == "named:staircase" and staircase["world"]["units"] == "l0"
    drawn = _post(client, auth, "random 7", random={"seed": 7, "holds": 9, "gap": [0.1, 0.2]}).json()
    assert drawn["source"] == "random:7"
    assert drawn["world"] == json.loads(json.dumps(world_to_document(random_world(7, holds=9, gap=(0.1, 0.2)))))
    page = client.get("/api/v1/worlds", params={"limit": 1}).json()
    assert page["total"] == 2 and page["items"][0]["name"] == "random 7" and page["next_cursor"]


@pytest.mark.parametrize(
    ("body", "loc", "says"),
    [
        ({"world": POSTED | {"left": {"points": [[-1.2, 0.0], [-1.2, 1.0], [-1.2, 0.5]]}}},
         "world.left.points[2]", "increase strictly"),
        ({"world": POSTED | {"right": {"points": [[1.2, 0.0], [1.2, 1.0]], "mu": [0.5, 0.5]}}},
         "world.right.mu", "one entry per segment"),
        ({"world": POSTED | {"right": {"points": [[1.2, 0.0], [1.2, 1.0]], "mu": [-0.5]}}},
         "world.right.mu[0]", ">= 0"),
        ({"world": POSTED | {"right": {"points": [[-1.5, 0.0], [-1.5, 3.0]]}}}, "world", "left"),
        ({"world": POSTED | {"units": "ft"}}, "world.units", "l0"),
        ({"named": "everest"}, "named", "staircase"),
        ({"random": {"seed": 3, "gap": [0.4, 0.1]}}, "random.gap", "gap"),
    ],
)  # fmt: skip
def test_a_malformed_world_is_a_422_naming_where(client, auth, body, loc, says):
    response = _post(client, auth, "bad", **body)
    assert response.status_code == 422, response.text
    detail = response.json()["detail"][0]
    assert detail["loc"][1].startswith(loc) and says in detail["msg"], detail
    assert client.get("/api/v1/worlds").json()["total"] == 0, "nothing stored"


@pytest.mark.parametrize("sources", [{}, {"named": "staircase", "random": {"seed": 1}}])
def test_a_world_comes_from_exactly_one_source(client, auth, sources):
    response = _post(client, auth, "either", **sources)
    assert response.status_code == 422 and "exactly one of world, named or random" in response.text


def test_names_are_unique(client, auth):
    assert _post(client, auth, "twin", named="staircase").status_code == 201
    taken = _post(client, auth, "twin", named="narrowing")
    assert taken.status_code == 409 and "a world named 'twin' exists" in taken.json()["detail"]
    other = _post(client, auth, "other", named="narrowing").json()
    assert client.patch(f"/api/v1/worlds/{other['id']}", json={"name": "twin"}, headers=auth).status_code == 409


def test_every_change_needs_the_token(client, auth):
    world = _post(client, auth, "guarded", named="staircase").json()
    assert client.post("/api/v1/worlds", json={"name": "x", "named": "staircase"}).status_code == 401
    assert client.patch(f"/api/v1/worlds/{world['id']}", json={"name": "y"}).status_code == 401
    assert client.delete(f"/api/v1/worlds/{world['id']}").status_code == 401
    assert client.get(f"/api/v1/worlds/{world['id']}").json()["name"] == "guarded"


def test_a_world_in_use_is_not_deleted_and_the_409_names_who_uses_it(client, auth):
    world = _post(client, auth, "used", named="staircase").json()
    run = client.post("/api/v1/runs", json=RUN | {"world_id": world["id"]}, headers=auth).json()
    assert client.get(f"/api/v1/worlds/{world['id']}").json()["runs"] == 1
    refused = client.delete(f"/api/v1/worlds/{world['id']}", headers=auth)
    assert refused.status_code == 409 and f"used by run {run['id']}" in refused.json()["detail"]
    assert client.get(f"/api/v1/worlds/{world['id']}").status_code == 200
    assert client.delete(f"/api/v1/runs/{run['id']}", headers=auth).status_code == 204
    assert client.delete(f"/api/v1/worlds/{world['id']}", headers=auth).status_code == 204


def test_a_run_in_a_world_is_parkour_climbs_climb_and_is_listed_by_world(client, auth):
    """A world posted in metres, climbed with a schedule of two legs: the stored touchdowns are
    sim_core's climb of the same world (read with the paper robot's leg length), the climb the sum
    of the feet's rises; the run says its world, and the list filters by it."""
    metres = {"units": "m", "left": {"points": [[-0.27, 0.0], [-0.24, 0.5], [-0.27, 2.0]], "mu": [1.2, None]},
              "right": {"points": [[0.27, 0.0], [0.27, 2.0]]}}  # fmt: skip
    world = _post(client, auth, "metres", world=metres).json()
    legs = [{"psi0_deg": 30, "zeta0": 0.9}, {"psi0_deg": 33, "zeta0": 0.88}]
    body = {"controls": legs, "start": {"xdot": -1.0, "ydot": 0.5}, "jumps": 6, "world_id": world["id"]}
    run = client.post("/api/v1/runs", json=body, headers=auth).json()
    paper = get_preset("paper")
    expected = climb_world(paper.to_model(), world_from_document(metres, paper.leg_length),
                           ControlSchedule.from_degrees([(30, 0.9), (33, 0.88)]), (-1.0, 0.5), 6).to_dict()  # fmt: skip
    assert run["world_id"] == world["id"] and run["results"]["touchdowns"] == expected["touchdowns"]
    assert run["results"]["failure"] == expected["failure"]
    feet = [td["y"] - (0.9 * math.sin(math.radians(30)) if td["jump"] % 2 == 0 else 0.88 * math.sin(math.radians(33)))
            for td in expected["touchdowns"]]  # fmt: skip
    assert run["climb"] == pytest.approx(feet[-1] - feet[0], abs=1e-12)
    assert run["jumps_completed"] == len(expected["touchdowns"]) - 1
    client.post("/api/v1/runs", json=RUN, headers=auth)  # parallel walls
    listed = client.get("/api/v1/runs", params={"world_id": world["id"]}).json()
    assert [item["id"] for item in listed["items"]] == [run["id"]] and listed["items"][0]["world_id"] == world["id"]
    assert client.post("/api/v1/runs", json=RUN | {"world_id": 999}, headers=auth).status_code == 404
    gait = client.post("/api/v1/runs", json=RUN | {"world_id": world["id"], "fixed_point": True}, headers=auth)
    assert gait.status_code == 422 and "gaits are found between parallel walls" in gait.text


def test_the_named_worlds_are_listed_in_the_openapi_document(client):
    """The panel's chooser of named worlds reads them there: sim_core's registry, one source."""
    named = client.get("/openapi.json").json()["components"]["schemas"]["WorldCreate"]["properties"]["named"]
    listed = named["x-named-worlds"]
    assert [world["name"] for world in listed] == list(NAMED_WORLDS)
    assert all(world["description"] == NAMED_WORLDS[world["name"]].description for world in listed)
