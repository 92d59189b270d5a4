"""Kill -9 in the middle of a batch job: the restarted service finishes it with exactly the
trials asked for — none lost, none duplicated — and the same numbers as an uninterrupted run."""

import math
import os
import signal
import time

import httpx
import numpy as np
import pytest
from sqlalchemy import create_engine, text

from sim_core import get_preset
from sim_core.model.noise import NoiseModel
from sim_core.robustness.mjtf import mjtf_study
from tests.helpers import start_service

pytestmark = pytest.mark.slow  # two service starts: ~15 s

# [s] for a job's progress: a hang guard (its workers run at niceness +10: a tenth of a core on a busy machine)
PROGRESS_WAIT_S = 300.0
SPEC = {"zeta0s": [0.86, 0.9], "trials": 1200, "cap": 1500, "seed": 3, "guess": {"xdot": -0.93, "ydot": 0.1}}


def test_kill_nine_mid_job_resumes_exactly(tmp_path):
    data_dir = tmp_path / "data"
    first = start_service(data_dir, 0, "--no-view")
    base = f"http://127.0.0.1:{first.port}/api/v1"
    try:
        token = (data_dir / "api_token").read_text().strip()
        job = httpx.post(f"{base}/jobs", json=SPEC, headers={"Authorization": f"Bearer {token}"}).json()
        total = job["total"]
        deadline = time.monotonic() + PROGRESS_WAIT_S
        while (completed := httpx.get(f"{base}/jobs/{job['id']}").json()["completed"]) < total // 4:
            assert time.monotonic() < deadline, "no progress"
            time.sleep(0.05)
    finally:
        os.kill(first.pid, signal.SIGKILL)
        first.wait()
    assert 0 < completed < total, f"the kill must land mid-job (completed {completed} of {total})"
    print(f"SIGKILL with {completed} of {total} trials committed")

    second = start_service(data_dir, 0, "--no-view")
    base = f"http://127.0.0.1:{second.port}/api/v1"
    try:
        deadline = time.monotonic() + PROGRESS_WAIT_S
        while (state := httpx.get(f"{base}/jobs/{job['id']}").json())["state"] != "done":
            assert state["state"] in ("queued", "running") and time.monotonic() < deadline, state
            time.sleep(0.1)
    finally:
        second.terminate()
        second.wait(30)

    engine = create_engine(f"sqlite:///{data_dir / 'parkourlab.sqlite3'}")
    with engine.connect() as connection:
        rows = connection.execute(
            text('SELECT level, "index", jumps FROM trials WHERE job_id = :job ORDER BY level, "index"'),
            {"job": job["id"]},
        ).all()
    assert len(rows) == total == len({(level, index) for level, index, _ in rows}), "none lost, none duplicated"
    print(f"after restart: {len(rows)} trials, {len({(level, index) for level, index, _ in rows})} distinct")
    study = mjtf_study(
        get_preset("paper").to_model(), math.radians(30), SPEC["zeta0s"], noise=NoiseModel(),
        trials=SPEC["trials"], cap=SPEC["cap"], seed=SPEC["seed"], guess=(-0.93, 0.1),
    )  # fmt: skip
    jumps = np.array([row.jumps for row in rows]).reshape(2, SPEC["trials"])
    for level, expected in enumerate(study.levels):
        np.testing.assert_array_equal(jumps[level], expected.jumps)


STUDY = {"kind": "foothold-study", "random_worlds": {"count": 6, "seed0": 20}, "goal_height_m": 0.5, "trials": 8}


def test_kill_nine_mid_foothold_study_resumes_exactly(tmp_path):
    """Its worlds are stored as they finish: after kill -9 the restarted service computes the rest,
    and the result is the command's on the same worlds (timings aside)."""
    from tests.backend.jobs.test_foothold_study import without_timings
    from tests.cli.helpers import json_of

    data_dir = tmp_path / "data"
    first = start_service(data_dir, 0, "--no-view")
    base = f"http://127.0.0.1:{first.port}/api/v1"
    try:
        token = (data_dir / "api_token").read_text().strip()
        job = httpx.post(f"{base}/jobs", json=STUDY, headers={"Authorization": f"Bearer {token}"}).json()
        deadline = time.monotonic() + PROGRESS_WAIT_S
        while (completed := httpx.get(f"{base}/jobs/{job['id']}").json()["completed"]) < 2:
            assert time.monotonic() < deadline, "no progress"
            time.sleep(0.05)
    finally:
        os.kill(first.pid, signal.SIGKILL)
        first.wait()
    assert 0 < completed < job["total"] == 6, f"the kill must land mid-job (completed {completed} of 6)"

    second = start_service(data_dir, 0, "--no-view")
    base = f"http://127.0.0.1:{second.port}/api/v1"
    try:
        deadline = time.monotonic() + PROGRESS_WAIT_S
        while (state := httpx.get(f"{base}/jobs/{job['id']}").json())["state"] != "done":
            assert state["state"] in ("queued", "running") and time.monotonic() < deadline, state
            time.sleep(0.1)
        result = httpx.get(f"{base}/jobs/{job['id']}/results").json()["result"]
    finally:
        second.terminate()
        second.wait(30)
    engine = create_engine(f"sqlite:///{data_dir / 'parkourlab.sqlite3'}")
    with engine.connect() as connection:
        chunks = connection.execute(text('SELECT "index" FROM job_chunks WHERE job_id = :job'), {"job": job["id"]})
        assert sorted(index for (index,) in chunks) == list(range(6)), "each world once"
    command = json_of("foothold-study", "--random", "6", "--seed0", "20", "--goal-height", "0.5", "--trials", "8")
    assert without_timings(result) == without_timings(command)
    print(f"SIGKILL with {completed} of 6 worlds stored; resumed to the command's result")


@pytest.mark.realtime  # the journal keeps the run to within a second of the kill: a real-time bound
def test_kill_nine_during_a_live_run_keeps_it_interrupted_to_the_last_second(tmp_path, virtual):
    """The run is stored as it starts and journaled while it runs: after kill -9 and a restart it
    is there, interrupted, with its touchdowns and frames to within a second of the kill; the
    robot, its heartbeats gone, disarms itself, and the restarted service arms nothing."""
    from backend.robot.messages import Fault, RobotState  # only the robot tests load the robot side

    robot, tracker_port = virtual
    data_dir = tmp_path / "data"
    first = start_service(data_dir, 0, "--no-view")
    base = f"http://127.0.0.1:{first.port}/api/v1"
    try:
        auth = {"Authorization": f"Bearer {(data_dir / 'api_token').read_text().strip()}"}
        connect = {"url": robot.url, "tracker_port": tracker_port}
        httpx.post(f"{base}/robot/connect", json=connect, headers=auth, timeout=10).raise_for_status()
        run = {"controls": [{"psi0_deg": 30.0, "zeta0": 0.87}, {"psi0_deg": 30.0, "zeta0": 0.9}], "jumps": 1000}
        httpx.post(f"{base}/robot/runs", json=run, headers=auth, timeout=10).raise_for_status()
        deadline = time.monotonic() + 60
        while (live := httpx.get(f"{base}/robot").json()["run"])["touchdowns"] < 6:
            assert time.monotonic() < deadline and live["active"], live
            time.sleep(0.05)
        seen = httpx.get(f"{base}/robot").json()["run"]
        time.sleep(1.0)  # what was seen a second before the kill must be stored
    finally:
        os.kill(first.pid, signal.SIGKILL)
        first.wait()
    killed_at = time.time()
    print(f"SIGKILL during live run {seen['id']} with {seen['touchdowns']} touchdowns seen")

    deadline = time.monotonic() + 10
    while robot.firmware.state != RobotState.DISARMED:  # its watchdog, not a DISARM: nobody is left to send one
        assert time.monotonic() < deadline, robot.firmware.state
        time.sleep(0.05)
    assert robot.firmware.faults & Fault.HEARTBEAT_LOST

    second = start_service(data_dir, 0, "--no-view")
    base = f"http://127.0.0.1:{second.port}/api/v1"
    try:
        stored = httpx.get(f"{base}/runs/{seen['id']}").json()
        status = httpx.get(f"{base}/robot").json()
    finally:
        second.terminate()
        second.wait(30)
    assert stored["kind"] == "robot" and stored["status"] == "interrupted", stored["status"]
    results = stored["results"]
    assert results["end_reason"].startswith("interrupted") and results["disarm"].startswith("not confirmed")
    assert len(results["touchdowns"]) >= seen["touchdowns"], "every touchdown seen a second before the kill is kept"
    assert stored["jumps_completed"] == len(results["touchdowns"]) - 1 and stored["has_trajectory"]
    lived = killed_at - seen["started"]  # [s] from the run's start to the kill
    assert lived - stored["duration_s"] < 1.5, "data to within a second of the kill (plus one journal period)"
    frames = results["tracker"]["frames"]
    print(f"after restart: {stored['status']}, {len(results['touchdowns'])} touchdowns, {frames} frames, "
          f"{stored['duration_s']:.2f} s of {lived:.2f} s")  # fmt: skip
    assert status["state"] == "disconnected" and robot.firmware.state == RobotState.DISARMED, "nothing re-armed"
