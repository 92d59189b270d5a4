"""parkourlab/jobs.py: batch jobs through the client.

Against the real service (tests/parkourlab/conftest.py, started once for the session): submit +
wait + results, a wait that times out and a cancelled job. Against a mock transport: the body each
typed ``submit_*`` sends (which the API's own request models must accept, every field given), the
requests ``job``, ``jobs``, ``wait`` and ``cancel`` make, and ``job_id``."""

from __future__ import annotations

import inspect
import json

import httpx
import pytest

from parkourlab import Client, JobFailed, JobTimeout
from parkourlab.jobs import job_id
from tests.parkourlab.conftest import QUICK_MJTF, QUICK_ZETA0S, WAIT_TIMEOUT

# An MJTF job that takes minutes: waited on briefly, then cancelled.
LONG_MJTF = {"zeta0s": [0.86, 0.88, 0.9], "trials": 4096, "cap": 1000, "seed": 2}
URL = "http://lab-pc:8000"


# The real service ---------------------------------------------------------------------------------
def test_job_submit_wait_results(client, quick_job):
    trials = QUICK_MJTF["trials"]
    assert quick_job["state"] == "done" and quick_job["completed"] == quick_job["total"] == len(QUICK_ZETA0S) * trials
    assert quick_job["spec"]["zeta0s"] == QUICK_ZETA0S and quick_job["spec"]["seed"] == QUICK_MJTF["seed"]
    results = client.results(quick_job)
    assert not results["partial"] and results["missing_zeta0s"] == []
    assert [(level["zeta0"], level["trials"]) for level in results["levels"]] == [(z, trials) for z in QUICK_ZETA0S]
    assert client.job(quick_job["id"]) == client.job(quick_job), "a job by its id or as the API gave it"
    assert quick_job["id"] in [job["id"] for job in client.jobs(state="done", page_size=1)]
    assert quick_job["id"] not in [job["id"] for job in client.jobs(state="failed")]


def test_wait_times_out_and_a_cancelled_job_fails(client, quick_job):
    job = client.submit_job("mjtf", **LONG_MJTF)
    try:
        with pytest.raises(JobTimeout) as late:
            client.wait(job, timeout=0.3, poll_interval=0.1)
        assert late.value.job["id"] == job["id"] and isinstance(late.value, TimeoutError)
    finally:
        client.cancel(job)
    cancelled = client.wait(job, timeout=WAIT_TIMEOUT, poll_interval=0.1, check=False)
    assert cancelled["state"] == "cancelled"
    with pytest.raises(JobFailed, match="cancelled"):
        client.wait(job, timeout=WAIT_TIMEOUT)
    assert client.results(job)["partial"], "a cancelled job's results stay partial"


# A mock transport ---------------------------------------------------------------------------------
def job(state: str, completed: int = 0, ident: int = 7) -> dict:
    return {"id": ident, "kind": "mjtf", "state": state, "completed": completed, "total": 4, "error": None}


class Service:
    """A stand-in for the API: records each request, answers ``answer(request)``."""

    def __init__(self, answer=lambda request: job("queued")):
        self.requests: list[httpx.Request] = []
        self.answer = answer

    def __call__(self, request: httpx.Request) -> httpx.Response:
        self.requests.append(request)
        return httpx.Response(200, json=self.answer(request))

    def client(self) -> Client:
        return Client(URL, token="secret", transport=httpx.MockTransport(self))

    def bodies(self) -> list[dict]:
        return [json.loads(request.content) for request in self.requests]


def submitted(submit) -> dict:
    """The body ``submit(client)`` posts to ``/api/v1/jobs``."""
    service = Service()
    with service.client() as client:
        submit(client)
    (request,) = service.requests
    assert (request.method, request.url.path) == ("POST", "/api/v1/jobs")
    assert request.headers["Authorization"] == "Bearer secret"
    return json.loads(request.content)


EVERY_FIELD = {
    "mjtf": lambda c: c.submit_mjtf(
        [0.86, 0.9], psi0_deg=28.0, trials=16, cap=500, seed=3, noise={"zeta0": 0.01},
        guess=(-0.93, -0.17), model={"preset": "paper", "mu": 0.8}, experiment_id=2,
    ),
    "sweep": lambda c: c.submit_sweep(
        zeta0_low=0.82, zeta0_high=0.92, steps=5, psi0_deg=30.0, basin_grid=4, basin_jumps=10, basin_jump_limit=80,
        guess={"xdot": -0.93, "ydot": -0.17}, model={"preset": "paper"}, experiment_id=2,
    ),
    "basin": lambda c: c.submit_basin(
        [(30, 0.87), {"psi0_deg": 30, "zeta0": 0.9}], period=2, guess=(-0.93, -0.17), grid=20, jumps=30,
        jump_limit=240, tolerance=0.05, model={"preset": "paper"}, experiment_id=2,
    ),
    "gaits": lambda c: c.submit_gaits([(30, 0.87), (30, 0.9)], period=2, grid=4, model={"alpha": 2.0}, experiment_id=2),
    "control-study": lambda c: c.submit_control_study(
        ["pid", "lqr"], target_m=0.5, seeds=20, seed0=3, jumps=100, psi0_deg=33.0, start_zeta0=0.88,
        noise={"pitch_drift_deg": 0.5}, model={"preset": "paper"}, experiment_id=2,
    ),
    "mfpt": lambda c: c.submit_mfpt(
        psi0_deg=31.0, zeta0=0.93, start=(-0.93, -0.17), guess=(-0.9, -0.2), noise={"velocity": 0.02}, grid=20,
        pitch_spacing=0.7, model={"preset": "paper"}, experiment_id=2,
    ),
    "loop-mfpt": lambda c: c.submit_loop_mfpt(
        "deadbeat", target_m=0.6, psi0_deg=34.0, start_zeta0=0.88, noise={"velocity": 0.05, "pitch_drift_deg": 0.0},
        replicas=50, runs=8, seed=4, model={"preset": "paper"}, experiment_id=2,
    ),
    "atlas": lambda c: c.submit_atlas(
        psi0_low_deg=20.0, psi0_high_deg=40.0, zeta0_low=0.85, zeta0_high=0.95, rows=4, columns=5, transient=200,
        model={"preset": "paper"}, experiment_id=2,
    ),
    "viability": lambda c: c.submit_viability(
        states=30, actions=10, psi0_low_deg=20.0, psi0_high_deg=45.0, zeta0_low=0.75, zeta0_high=0.97,
        model={"preset": "paper"}, experiment_id=2,
    ),
    "foothold-study": lambda c: c.submit_foothold_study(
        0.5, world_id=3, trials=5, cap=100, seed=1, noise={"velocity": 0.01},
        state=(-0.9, 0.1), model={"preset": "paper"}, experiment_id=2,
    ),
    "plan": lambda c: c.submit_plan(
        3, 0.5, launch_gait=False, attempts=10, replans=1, cap=50, seed=2, noise={"velocity": 0.01},
        state=(-0.9, 0.1), importance_sampling={"trials": 20, "scale": 2.0, "draws": ["psi0"], "first_leg": True},
        model={"preset": "paper"}, experiment_id=2,
    ),
    "world-mjtf": lambda c: c.submit_world_mjtf(
        3, [(30, 0.9)], goal_height_m=0.5, trials=5, cap=50, seed=2, noise={"velocity": 0.01}, state=(-0.9, 0.1),
        model={"preset": "paper"}, experiment_id=2,
    ),
    "reach": lambda c: c.submit_reach(
        3, psi0_range=(25.0, 35.0), psi0_steps=3, zeta0_range=(0.86, 0.92), zeta0_steps=2, jumps=30, foot_y=0.1,
        state=(-1.0, 0.5), model={"preset": "paper"}, experiment_id=2,
    ),
}  # fmt: skip


@pytest.mark.parametrize("kind", sorted(EVERY_FIELD))
def test_each_submit_sends_a_body_the_api_takes(kind):
    from backend.jobs import JOB_KINDS

    body = submitted(EVERY_FIELD[kind])
    request_model = JOB_KINDS[kind]
    either = {"foothold-study": {"random_worlds"}}.get(kind, set())  # a stored world or random ones, not both
    assert set(body) == set(request_model.model_fields) - either, "every field given is sent, under the API's name"
    accepted = request_model.model_validate(body)  # strict: an unknown or misspelt field is refused
    assert accepted.kind == kind and accepted.experiment_id == 2


def test_typed_submits_name_every_field_of_their_kind():
    """A field added to a job's request model is a parameter of its ``submit_*`` (or this fails)."""
    from backend.jobs import JOB_KINDS

    for kind, request_model in JOB_KINDS.items():
        parameters = set(inspect.signature(getattr(Client, f"submit_{kind.replace('-', '_')}")).parameters) - {"self"}
        assert parameters == set(request_model.model_fields) - {"kind"}, kind


def test_submits_convert_legs_and_states_and_leave_defaults_to_the_service():
    assert submitted(lambda c: c.submit_mjtf([0.9])) == {"kind": "mjtf", "zeta0s": [0.9]}
    assert submitted(lambda c: c.submit_sweep()) == {"kind": "sweep"}
    basin = submitted(lambda c: c.submit_basin([(30, 0.87), (31, 0.9)], guess=(-0.9, -0.2)))
    assert basin == {
        "kind": "basin",
        "controls": [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 31, "zeta0": 0.9}],
        "guess": {"xdot": -0.9, "ydot": -0.2},
    }
    gaits = submitted(lambda c: c.submit_job("gaits", controls=[{"psi0_deg": 30, "zeta0": 0.9}], grid=None))
    assert gaits == {"kind": "gaits", "controls": [{"psi0_deg": 30, "zeta0": 0.9}]}


def test_job_id_of_an_id_or_the_apis_dict():
    assert job_id(7) == 7 and job_id({"id": 7, "state": "done"}) == 7 and job_id({"id": "7"}) == 7
    with pytest.raises(KeyError):
        job_id({"state": "done"})


def test_job_results_and_cancel_ask_for_the_job_by_id():
    service = Service()
    with service.client() as client:
        client.job(7)
        client.results({"id": 7})
        client.cancel(job("running"))
    assert [(r.method, r.url.path) for r in service.requests] == [
        ("GET", "/api/v1/jobs/7"),
        ("GET", "/api/v1/jobs/7/results"),
        ("POST", "/api/v1/jobs/7/cancel"),
    ]


def test_jobs_follows_every_page_with_its_filters():
    pages = {None: {"items": [job("done", 4, 9), job("done", 4, 8)], "next_cursor": 8},
             "8": {"items": [job("done", 4, 3)], "next_cursor": None}}  # fmt: skip
    service = Service(lambda request: pages[request.url.params.get("cursor")])
    with service.client() as client:
        listed = list(client.jobs(state="done", experiment_id=2, page_size=2))
    assert [listed_job["id"] for listed_job in listed] == [9, 8, 3]
    params = [dict(request.url.params) for request in service.requests]
    assert params == [
        {"state": "done", "experiment_id": "2", "limit": "2"},
        {"state": "done", "experiment_id": "2", "limit": "2", "cursor": "8"},
    ]


def test_wait_polls_the_job_until_it_is_final():
    answers = iter([job("queued"), job("running", 2), job("done", 4)])
    service = Service(lambda request: next(answers))
    with service.client() as client:
        final = client.wait({"id": 7}, poll_interval=0)
    assert final["state"] == "done" and len(service.requests) == 3
    assert {request.url.path for request in service.requests} == {"/api/v1/jobs/7"}


def test_wait_raises_for_a_failed_job_unless_told_not_to():
    failed = job("failed", 1) | {"error": "worker died"}
    service = Service(lambda request: failed)
    with service.client() as client:
        with pytest.raises(JobFailed, match="worker died") as raised:
            client.wait(7, poll_interval=0)
        assert raised.value.job == failed
        assert client.wait(7, poll_interval=0, check=False) == failed


def test_a_controllers_mfpt_names_the_law_and_leaves_the_rest_to_the_service():
    body = submitted(lambda c: c.submit_loop_mfpt("lqr", noise={"velocity": 0.05}, replicas=20, runs=2))
    assert body == {"kind": "loop-mfpt", "controller": "lqr", "noise": {"velocity": 0.05}, "replicas": 20, "runs": 2}


def test_the_job_kinds_are_the_services_registry(client):
    from backend.jobs import KINDS

    kinds = client.job_kinds()
    assert [kind["name"] for kind in kinds] == [kind.name for kind in KINDS]
    assert all(hasattr(Client, f"submit_{kind['name'].replace('-', '_')}") for kind in kinds), "a typed submit each"
