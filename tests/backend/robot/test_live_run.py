"""A live run's records: one writer, immutable snapshots for everyone else, a journal queue."""

import dataclasses

import pytest

from backend.robot.live_run import LiveRun, Record, RunSnapshot
from backend.robot.messages import Leg
from backend.robot.touchdown import Touchdown
from sim_core.model.controls import LegControl
from sim_core.model.walls import Wall

TOUCHDOWN = Touchdown(0, 1.5, Wall.RIGHT, (-0.9, 0.1), 0.4, 0.35, 8)
CONTROL = LegControl.from_degrees(30.0, 0.87)


def test_a_snapshot_is_immutable_and_replaced_whole():
    run = LiveRun(jumps=4, max_seconds=60.0, run_id=7)
    before = run.snapshot
    run.record("touchdown", (TOUCHDOWN, CONTROL), run.touchdowns)
    run.commanded[Leg.LEFT] = CONTROL
    assert before.touchdowns == () and run.snapshot is before, "nothing shows until published"
    run.publish()
    after = run.snapshot
    assert after is not before and after.touchdowns == (TOUCHDOWN,) and after.command_for(Leg.LEFT) == CONTROL
    assert isinstance(after.touchdowns, tuple) and isinstance(after.commanded, tuple)
    run.touchdowns.append(TOUCHDOWN)  # the loop goes on writing: a reader's snapshot does not move
    assert len(after.touchdowns) == 1
    with pytest.raises(dataclasses.FrozenInstanceError):
        after.active = False  # type: ignore[misc]


def test_records_reach_the_journal_once_in_order():
    run = LiveRun(jumps=4, max_seconds=60.0)
    run.record("command", {"leg": "left", "why": "start"}, run.commands)
    run.record("touchdown", (TOUCHDOWN, CONTROL), run.touchdowns)
    drained = [run.journal.get_nowait() for _ in range(2)]
    assert drained == [Record("command", {"leg": "left", "why": "start"}), Record("touchdown", (TOUCHDOWN, CONTROL))]
    assert run.journal.empty() and run.touchdowns == [TOUCHDOWN]


def test_the_first_stop_asked_is_the_runs_reason():
    run = LiveRun(jumps=4, max_seconds=60.0)
    assert run.stop_reason() is None
    run.stop("e-stop")
    run.stop("stopped")
    assert run.stop_reason() == "e-stop"


def test_status_names_the_stored_run():
    status = RunSnapshot(run_id=3, started=10.0, jumps=4, max_seconds=60.0).to_status()
    assert (status["id"], status["stored_run_id"], status["active"], status["touchdowns"]) == (3, 3, True, 0)
    assert set(status) >= {"started", "jumps", "max_seconds", "commands", "end_reason", "disarm"}
    assert (status["world_id"], status["plan_job_id"]) == (None, None), "parallel walls, no plan"


def test_a_run_shows_the_world_it_climbs_and_the_plan_it_follows():
    run = LiveRun(jumps=4, max_seconds=60.0, run_id=7, world_id=2, plan_job_id=5)
    assert (run.snapshot.world_id, run.snapshot.plan_job_id) == (2, 5), "from its first snapshot (the live view's)"
    run.publish()
    assert run.snapshot.to_status()["world_id"] == 2 and run.snapshot.to_status()["plan_job_id"] == 5


def test_the_status_carries_the_newest_commands_as_plain_json():
    import json

    import numpy as np

    from backend.robot.run_snapshot import RECENT_COMMANDS

    run = LiveRun(jumps=4, max_seconds=60.0, run_id=7)
    assert run.snapshot.to_status()["recent_commands"] == [], "nothing sent yet"
    target = {"touchdown": np.int64(2), "side": "left", "segment": np.int64(6), "x_m": np.float64(-0.27), "y_m": 0.44}
    command = {"time": 1.0, "leg": "left", "psi0_deg": 32.5, "zeta0": 0.8, "why": "plan after touchdown 0",
               "target": target, "placed": "placed", "clipped": False}  # fmt: skip
    run.record("command", command, run.commands)
    run.publish()
    status = run.snapshot.to_status()
    assert status["commands"] == 1 and json.loads(json.dumps(status["recent_commands"])) == [
        {**command, "target": {**target, "touchdown": 2, "segment": 6, "x_m": -0.27}}
    ], "the panel's journal row, as the stored journal will have it"
    for k in range(2, 8):
        run.record("command", {**command, "time": float(k)}, run.commands)
    run.publish()
    status = run.snapshot.to_status()
    assert status["commands"] == 7 and [sent["time"] for sent in status["recent_commands"]] == [
        float(k) for k in range(8 - RECENT_COMMANDS, 8)
    ], "the newest, oldest first: the panel numbers them from the count"
