"""More clients at once than the store has connections: every request is answered, none fails.

With a session per request held from the route until FastAPI had serialised the answer (which for
a sync route waits for a request thread), 15 requests could hold the pool's every connection while
the 4 request threads waited for one: at 50 clients the service hung for the pool's 30 s timeout and
answered 500s (``scripts/bench_load.py --clients 50``; this test, on that code: no answer within 400 s).
Now a connection is held only while a request thread works (``deps.Database``).
"""

import collections
import concurrent.futures

from fastapi.testclient import TestClient

from backend.api.app import create_app
from tests.backend.api.bodies import RUN
from tests.helpers import answer_within

CLIENTS = 60  # the SQLite pool holds 5 connections and lends 10 more
REQUESTS_EACH = 6
# Reads that each hold a connection, and their serialised answers: a page, a run, the health check.
READS = ["/api/v1/runs?limit=50", "/api/v1/runs/1", "/api/v1/health", "/api/v1/runs?zeta0_min=0.85&zeta0_max=0.95"]


def test_sixty_clients_at_once_are_all_answered(settings, compute):
    with TestClient(create_app(settings, compute=compute), raise_server_exceptions=False) as client:
        auth = {"Authorization": f"Bearer {(settings.data_dir / 'api_token').read_text().strip()}"}
        for _ in range(3):
            assert client.post("/api/v1/runs", json=RUN, headers=auth).status_code == 201

        def one_client(k: int) -> list[int]:
            return [client.get(READS[(k + n) % len(READS)]).status_code for n in range(REQUESTS_EACH)]

        def all_clients() -> collections.Counter:
            with concurrent.futures.ThreadPoolExecutor(CLIENTS) as pool:
                return collections.Counter(code for codes in pool.map(one_client, range(CLIENTS)) for code in codes)

        codes = answer_within(120, all_clients)  # a pool that deadlocks waits 30 s per request, then 500s
    assert codes == {200: CLIENTS * REQUESTS_EACH}
