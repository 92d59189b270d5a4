"""Concurrent edits of one record through the real app (issue 14): each edit is atomic.

Four clients PATCH one run's tags and notes at the same moment, a hundred rounds. Before the fix
(the ORM diffed the tags it had read against the new ones, outside any lock) 46 of the 400
responses were 500s (``UNIQUE constraint failed: run_tags``) and 64 of the 100 rounds ended with
tags that no request sent (two edits' tags together). Now every change takes the write lock before
it reads (``records.locked``): all 400 answer 200 and every round ends with exactly one request's
tags and notes. The same lock closes the PATCH/DELETE and run-create/experiment-delete races below.

``DATABASE_URL=postgresql+psycopg://…`` runs these against PostgreSQL (there the lock is ``SELECT …
FOR UPDATE``). Against PostgreSQL 15, before the fix: 88 of 400 PATCHes 500 and 92 of 100 rounds
with foreign tags; 26 of 40 PATCHes racing a DELETE 500; after: all four pass.
"""

import collections
import threading

import pytest
from fastapi.testclient import TestClient

from backend.api.app import create_app
from tests.backend.api.bodies import RUN

CLIENTS = 4
ROUNDS = 100


@pytest.fixture
def client(settings):
    """The real app; a server error is a 500 to count, not an exception in a client thread."""
    with TestClient(create_app(settings), raise_server_exceptions=False) as test_client:
        yield test_client


def _race(client, auth, path: str, bodies_of_round, read_back):
    """Send each round's bodies at once (one thread each); the status counts and the rounds whose
    stored state is not one of the bodies sent."""
    codes: collections.Counter = collections.Counter()
    foreign = []
    for round_ in range(ROUNDS):
        bodies = bodies_of_round(round_)
        barrier = threading.Barrier(len(bodies))

        def patch(body, barrier=barrier):
            barrier.wait()
            codes[client.patch(path, json=body, headers=auth).status_code] += 1

        threads = [threading.Thread(target=patch, args=(body,)) for body in bodies]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        stored = read_back(client.get(path).json())
        if stored not in [read_back(body) for body in bodies]:
            foreign.append((round_, stored))
    return codes, foreign


def test_concurrent_tag_and_note_edits_of_a_run_are_atomic(client, auth):
    run = client.post("/api/v1/runs", json=RUN | {"jumps": 2, "tags": ["start"]}, headers=auth).json()["id"]

    def bodies(round_):
        # Two overlapping sets (a lost race used to insert a tag twice: UNIQUE failed) and two
        # disjoint ones (a lost race used to keep both: a union nobody sent).
        tag_sets = [["all", f"r{round_}", f"t{k}"] for k in range(2)] + [[f"r{round_}k{k}"] for k in (2, 3)]
        return [{"tags": tags, "notes": f"round {round_} client {k}"} for k, tags in enumerate(tag_sets)]

    codes, foreign = _race(
        client, auth, f"/api/v1/runs/{run}", bodies, lambda body: (sorted(body["tags"]), body["notes"])
    )
    # By status code, and the rounds that ended with tags or notes that no request sent:
    assert (dict(codes), len(foreign)) == ({200: CLIENTS * ROUNDS}, 0), foreign[:5]


def test_concurrent_experiment_edits_are_atomic(client, auth):
    experiment = client.post("/api/v1/experiments", json={"name": "shared"}, headers=auth).json()["id"]

    def bodies(round_):
        return [{"tags": [f"r{round_}", f"c{k}"], "notes": f"{round_}.{k}"} for k in range(CLIENTS)]

    codes, foreign = _race(
        client, auth, f"/api/v1/experiments/{experiment}", bodies, lambda body: (body["tags"], body["notes"])
    )
    assert (dict(codes), len(foreign)) == ({200: CLIENTS * ROUNDS}, 0), foreign[:5]


def test_editing_a_run_while_it_is_deleted_is_a_404_not_a_500(client, auth):
    """A PATCH racing a DELETE of the same run used to insert tags for a run already gone
    (FOREIGN KEY failed: 13 of 40 PATCHes were 500s); under the write lock it finds the run, or
    finds it gone (404)."""
    codes: collections.Counter = collections.Counter()
    for round_ in range(20):
        run = client.post("/api/v1/runs", json=RUN | {"jumps": 2}, headers=auth).json()["id"]
        barrier = threading.Barrier(3)

        def call(method, body=None, barrier=barrier, run=run):
            barrier.wait()
            response = client.request(method, f"/api/v1/runs/{run}", json=body, headers=auth)
            codes[method, response.status_code] += 1

        threads = [threading.Thread(target=call, args=("PATCH", {"tags": [f"x{round_}", f"y{k}"]})) for k in (0, 1)]
        threads.append(threading.Thread(target=call, args=("DELETE",)))
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        assert client.get(f"/api/v1/runs/{run}").status_code == 404
    assert codes["DELETE", 204] == 20
    assert set(codes) <= {("DELETE", 204), ("PATCH", 200), ("PATCH", 404)}, codes


def _create_while_deleting_its_experiment(client, auth, path: str, body: dict) -> collections.Counter:
    """Twenty rounds of POSTing ``body`` into a new experiment at ``path`` while another client
    DELETEs that experiment, both released at once: how often each pair of (POST, DELETE) statuses came."""
    outcomes: collections.Counter = collections.Counter()
    for _ in range(20):
        experiment = client.post("/api/v1/experiments", json={"name": "doomed"}, headers=auth).json()["id"]
        barrier = threading.Barrier(2)
        codes = {}

        def create(barrier=barrier, experiment=experiment, codes=codes):
            barrier.wait()
            codes["POST"] = client.post(path, json=body | {"experiment_id": experiment}, headers=auth).status_code

        def remove(barrier=barrier, experiment=experiment, codes=codes):
            barrier.wait()
            codes["DELETE"] = client.delete(f"/api/v1/experiments/{experiment}", headers=auth).status_code

        threads = [threading.Thread(target=create), threading.Thread(target=remove)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        outcomes[codes["POST"], codes["DELETE"]] += 1
    return outcomes


def test_a_run_added_to_an_experiment_being_deleted_is_stored_or_refused_never_a_500(client, auth):
    """Creating a run in an experiment while it is deleted: the run is stored (and the delete is a
    409, the experiment still has runs) or the experiment is gone first (404, delete 204). Checks and
    writes used to be apart: 5 of 20 rounds had a 500 (FOREIGN KEY failed), and 2 answered 201 and
    204 — the run stored, then detached from its deleted experiment (the ORM nulled its experiment_id)."""
    outcomes = _create_while_deleting_its_experiment(client, auth, "/api/v1/runs", RUN | {"jumps": 2})
    assert set(outcomes) <= {(201, 409), (404, 204)}, outcomes


def test_a_job_added_to_an_experiment_being_deleted_is_stored_or_refused_never_a_500(client, auth):
    """The same race for a job: before the fix the job's experiment was checked, then the job
    written apart from the check, so a delete between them was a 500 (FOREIGN KEY failed): 7 of 20
    rounds on SQLite. Now the job is stored under the experiment's lock (the delete is then a 409:
    an experiment keeps its jobs as its record) or the experiment is gone first (404, delete 204)."""
    job = {"zeta0s": [0.9], "trials": 1, "cap": 2}
    outcomes = _create_while_deleting_its_experiment(client, auth, "/api/v1/jobs", job)
    assert set(outcomes) <= {(202, 409), (404, 204)}, outcomes
