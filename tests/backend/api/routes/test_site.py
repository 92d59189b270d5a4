"""The service itself: health, the panel, offline docs (backend/api/routes/site.py)."""


def test_health_index_and_offline_docs(client):
    assert client.get("/api/v1/health").json()["status"] == "ok"
    page = client.get("/")
    assert page.status_code == 200 and "/docs" in page.text
    docs = client.get("/docs").text
    assert "cdn" not in docs.lower() and "/static/swagger/swagger-ui-bundle.js" in docs, "no CDN at run time"
    assert client.get("/static/swagger/swagger-ui-bundle.js").status_code == 200
    assert client.get("/openapi.json").json()["info"]["title"] == "ParkourLab"


def test_auth_says_whether_the_token_is_accepted(client, auth):
    """What the panel shows beside its token field: 200 for the service's token, 401 otherwise."""
    assert client.get("/api/v1/auth", headers=auth).json() == {"accepted": True}
    assert client.get("/api/v1/auth").status_code == 401
    assert client.get("/api/v1/auth", headers={"Authorization": "Bearer not-the-token"}).status_code == 401
