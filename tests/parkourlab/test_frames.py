"""parkourlab/frames.py: results as pandas DataFrames, pandas needed only when a frame is asked for.

Which table each kind of job makes, and the refusals (a basin, a job with no result yet), are
checked with a stand-in for pandas, so they run where pandas is not installed (the project does
not need it); the frames themselves, from plain data and from the real service (conftest.py), with
pandas where it is installed."""

from __future__ import annotations

import sys
from importlib.util import find_spec
from types import SimpleNamespace

import httpx
import pytest

from parkourlab import Client
from parkourlab.frames import NO_PANDAS, _levels, require_pandas, results_frame, runs_frame
from tests.parkourlab.conftest import QUICK_MJTF, QUICK_ZETA0S, ZETA0S

needs_pandas = pytest.mark.skipif(find_spec("pandas") is None, reason="pandas is not installed")
LEVELS = [
    {"zeta0": 0.86, "trials": 4, "mean": 12.5, "std": 3.0, "outcomes": {"capped": 1, "slip": 3}},
    {"zeta0": 0.9, "trials": 4, "mean": 30.0, "std": 0.0, "outcomes": {"capped": 4}},
    {"zeta0": 0.94, "trials": 2, "mean": 2.0, "std": 1.0, "outcomes": {"wall_miss": 2}},
]


def results(kind: str, result=None, **more) -> dict:
    return {"job": {"id": 5, "kind": kind, "state": "done"}, "partial": False, "result": result} | more


@pytest.fixture
def fake_pandas(monkeypatch) -> SimpleNamespace:
    """A stand-in for pandas: each frame comes back as ``(how it was made, its rows)``."""
    fake = SimpleNamespace(
        DataFrame=lambda rows: ("DataFrame", rows), json_normalize=lambda rows: ("json_normalize", rows)
    )
    monkeypatch.setitem(sys.modules, "pandas", fake)
    return fake


@pytest.fixture
def no_pandas(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now fails


# Without pandas -----------------------------------------------------------------------------------
def test_mjtf_levels_one_row_each_with_a_column_per_outcome():
    rows = _levels(LEVELS)
    assert rows[0] == {
        "zeta0": 0.86, "trials": 4, "mean": 12.5, "std": 3.0,
        "outcome.capped": 1, "outcome.slip": 3, "outcome.wall_miss": 0,
    }  # fmt: skip
    assert [list(row) for row in rows] == [list(rows[0])] * 3, "every row has every outcome, in one order"
    assert [(row["outcome.capped"], row["outcome.slip"], row["outcome.wall_miss"]) for row in rows] == [
        (1, 3, 0),
        (4, 0, 0),
        (0, 0, 2),
    ]
    assert _levels([]) == []


def test_each_kind_of_job_its_table(fake_pandas):
    assert results_frame(results("mjtf", levels=LEVELS)) == ("DataFrame", _levels(LEVELS))
    assert results_frame(results("mjtf", levels=None)) == ("DataFrame", []), "no level has trials yet"
    points = [{"zeta0": 0.85, "climb": 0.1}, {"zeta0": 0.9, "climb": 0.2}]
    assert results_frame(results("sweep", {"points": points, "psi0_deg": 30})) == ("json_normalize", points)
    gaits = [{"period": 1, "state": {"xdot": -0.9, "ydot": -0.2}}]
    assert results_frame(results("gaits", {"gaits": gaits})) == ("json_normalize", gaits)
    controllers = [{"name": "pid", "failures": 3, "failure_codes": {"slip": 3}}, {"name": "lqr", "failures": 0}]
    study = {"controllers": controllers, "target_m": 0.55, "plots": {}}
    assert results_frame(results("control-study", study)) == ("json_normalize", controllers)


def test_a_basin_or_a_job_without_its_result_is_refused(fake_pandas):
    with pytest.raises(ValueError, match=r"a basin job's result is not a table: use Client.results\(job\)\['result'\]"):
        results_frame(results("basin", {"grid": [[1, 0], [0, 1]]}))
    running = results("sweep") | {"job": {"id": 5, "kind": "sweep", "state": "running"}, "partial": True}
    with pytest.raises(ValueError, match=r"job 5 has no result yet \(state running\)"):
        results_frame(running)


def test_without_pandas_an_import_error_says_how_to_get_it(no_pandas):
    with pytest.raises(ImportError, match="pip install pandas") as missing:
        require_pandas()
    assert missing.value.name == "pandas" and str(missing.value) == NO_PANDAS
    with pytest.raises(ImportError, match="pip install pandas"):
        runs_frame([{"id": 1, "created_at": "2026-12-03T10:00:00Z"}])
    with pytest.raises(ImportError, match="pip install pandas"):
        results_frame(results("mjtf", levels=LEVELS))


def test_the_clients_frames_say_so_before_any_request(no_pandas):
    requests = []
    transport = httpx.MockTransport(lambda request: requests.append(request) or httpx.Response(200, json=[]))
    with Client("http://lab-pc:8000", transport=transport) as client:
        with pytest.raises(ImportError, match="pip install pandas"):
            client.runs_frame(tag="paging")
        with pytest.raises(ImportError, match="pip install pandas"):
            client.results_frame(5)
    assert requests == []


# With pandas --------------------------------------------------------------------------------------
@needs_pandas
def test_runs_frame_indexed_by_id_with_utc_times():
    records = [
        {"id": 3, "created_at": "2026-12-03T10:00:00Z", "climb": 0.4, "leg0.zeta0": 0.9},
        {"id": 4, "created_at": "2026-12-03T12:30:00.250000+02:00", "climb": 0.1, "leg0.zeta0": 0.86},
    ]
    frame = runs_frame(records)
    assert list(frame.index) == [3, 4] and frame.index.name == "id"
    assert list(frame.columns) == ["created_at", "climb", "leg0.zeta0"]
    assert str(frame["created_at"].dt.tz) == "UTC"
    assert [stamp.isoformat() for stamp in frame["created_at"]] == [
        "2026-12-03T10:00:00+00:00",
        "2026-12-03T10:30:00.250000+00:00",
    ]
    assert runs_frame([]).empty


@needs_pandas
def test_results_frames_from_plain_data():
    levels = results_frame(results("mjtf", levels=LEVELS))
    assert list(levels.columns) == [
        "zeta0", "trials", "mean", "std", "outcome.capped", "outcome.slip", "outcome.wall_miss",
    ]  # fmt: skip
    assert list(levels["outcome.capped"]) == [1, 4, 0]
    points = [{"zeta0": 0.85, "gait": {"max_abs_eig": 0.5}}, {"zeta0": 0.9, "gait": {"max_abs_eig": 0.7}}]
    sweep = results_frame(results("sweep", {"points": points}))
    assert list(sweep.columns) == ["zeta0", "gait.max_abs_eig"] and list(sweep["gait.max_abs_eig"]) == [0.5, 0.7]


@needs_pandas  # a mark, not importorskip: without pandas the service is not started for it
def test_frames_from_the_service(client, paging_runs, quick_job):
    frame = client.runs_frame(tag="paging")
    assert sorted(frame.index) == sorted(run["id"] for run in paging_runs)
    assert sorted(frame["leg0.zeta0"]) == ZETA0S and str(frame["created_at"].dtype).startswith("datetime64")
    levels = client.results_frame(quick_job)
    assert list(levels["zeta0"]) == QUICK_ZETA0S and list(levels["trials"]) == [QUICK_MJTF["trials"]] * 2
