"""The service itself: health, the panel, offline docs (backend/api/routes/site.py)."""


def test_health_index_and_offline_docs(client):
    assert client.get("/api/v1/health").json()["status"] == "ok"
    page = client.get("/")
    assert page.status_code == 200 and "/docs" in page.text
    docs = client.get("/docs").text
    assert "cdn" not in docs.lower() and "/static/swagger/swagger-ui-bundle.js" in docs, "no CDN at run time"
    assert client.get("/static/swagger/swagger-ui-bundle.js").status_code == 200
    assert client.get("/openapi.json").json()["info"]["title"] == "ParkourLab"
