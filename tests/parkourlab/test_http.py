"""parkourlab/_http.py: where the token and the URL come from, and query parameters."""

from datetime import UTC, datetime

import httpx
import pytest

from backend.workers.pools import QUICK_TIMEOUT
from parkourlab import Client, ServiceUnavailable, ServiceUnreachable
from parkourlab._http import DEFAULT_TIMEOUT, Http, client_name, find_token, is_loopback, query, service_url


@pytest.fixture
def clean_env(monkeypatch, tmp_path):
    for name in ("PARKOUR_API_TOKEN", "PARKOUR_URL", "PARKOUR_DATA_DIR"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_the_token_from_the_environment_first(clean_env, monkeypatch):
    (clean_env / "data").mkdir()
    (clean_env / "data" / "api_token").write_text("from-the-file\n")
    assert find_token("http://127.0.0.1:8000") == "from-the-file"
    monkeypatch.setenv("PARKOUR_API_TOKEN", "from-the-env")
    assert find_token("http://127.0.0.1:8000") == "from-the-env"


def test_the_token_file_of_the_data_directory(clean_env, monkeypatch):
    (clean_env / "elsewhere").mkdir()
    (clean_env / "elsewhere" / "api_token").write_text("abc\n")
    monkeypatch.setenv("PARKOUR_DATA_DIR", str(clean_env / "elsewhere"))
    assert find_token("http://localhost:8000") == "abc"
    assert find_token("http://lab-pc:8000") is None, "a remote service never gets the local token"
    monkeypatch.setenv("PARKOUR_DATA_DIR", str(clean_env / "nothing"))
    assert find_token("http://localhost:8000") is None


@pytest.mark.parametrize(
    ("url", "local"),
    [("http://127.0.0.1:8000", True), ("http://localhost", True), ("http://[::1]:8000", True),
     ("http://10.0.0.2:8000", False), ("http://lab-pc:8000", False)],
)  # fmt: skip
def test_loopback(url, local):
    assert is_loopback(url) is local


def test_the_url(clean_env, monkeypatch):
    assert service_url(None) == "http://127.0.0.1:8000"
    monkeypatch.setenv("PARKOUR_URL", "http://lab-pc:8000/")
    assert service_url(None) == "http://lab-pc:8000"
    assert service_url("http://other:9000") == "http://other:9000"


def test_query_parameters():
    when = datetime(2026, 12, 3, tzinfo=UTC)
    got = query({"tag": "a", "cursor": None, "created_after": when, "only_differences": False, "ids": [1, 2]})
    assert got == {"tag": "a", "created_after": "2026-12-03T00:00:00+00:00", "only_differences": "false", "ids": [1, 2]}


@pytest.mark.parametrize(
    ("name", "sent"),
    [("batch-trials", "batch-trials"), ("lab pc <1>", "lab-pc--1-"), ("x" * 80, "x" * 64)],
)
def test_the_client_names_itself_as_the_header_allows(name, sent):
    assert client_name(name) == sent


def test_by_default_the_client_is_python_at_this_host():
    assert client_name(None).startswith("python@")


def _answering(handler) -> Http:
    return Http("http://lab-pc:8000", None, DEFAULT_TIMEOUT, httpx.MockTransport(handler), "test")


def test_a_503_raises_with_the_services_own_message():
    busy = "busy: 64 quick computations are waiting already; retry shortly"
    http = _answering(lambda request: httpx.Response(503, json={"detail": busy}, headers={"Retry-After": "1"}))
    with pytest.raises(ServiceUnavailable) as raised:
        http.call("POST", "/api/v1/runs", body={})
    assert raised.value.status == 503 and raised.value.detail == busy
    assert str(raised.value) == f"POST /api/v1/runs: 503 service unavailable: {busy}"


def test_the_client_waits_longer_than_the_service_gives_a_computation():
    """Issue 40: both gave up at 60 s, and the script saw a ReadTimeout, not the service's 503."""
    assert DEFAULT_TIMEOUT > QUICK_TIMEOUT
    assert Client("http://lab-pc:8000")._http.client.timeout.read == DEFAULT_TIMEOUT


def test_no_answer_in_time_is_unreachable_and_says_it_was_the_clients_timeout():
    def slow(request):
        raise httpx.ReadTimeout("timed out", request=request)

    with pytest.raises(ServiceUnreachable, match=r"no answer within the client's timeout \(ReadTimeout\)"):
        _answering(slow).call("GET", "/api/v1/runs")
