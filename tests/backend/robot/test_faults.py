"""Fault scenarios against the link and its supervisor, on the pty rig (tests/robot_rig.py).

Line noise at many times a real line's rate, the radio out of range and back, the radio unplugged
and plugged in again, a write that went out but whose thread was late back (an expected failure:
a bug), and a link flapping for two minutes. A foreign radio's TELEMETRY(disarmed)
during a live run is tests/backend/services/test_robot.py's (the run goes on; counted); here every
flood burst carries one too, and each is counted.
"""

import logging
import os
import time

import pytest

from backend.robot.firmware import Firmware
from backend.robot.link import WRITE_TIMEOUT, LinkState, RobotLink
from backend.robot.messages import Kind, RobotState
from backend.robot.supervisor import LinkSupervisor
from tests.helpers import answer_within
from tests.robot_rig import ANSWER_BOUND_S, LinkCalls, PtyRobot, Radio, flap_supervised, link_threads, wait_for

FLOOD_BURSTS = 300  # bursts before the e-stop, and as many after it (100 kB/s: about 1.2 s each)
LOST_WITHIN_S = 3.0  # [s] the link sees the drop (its heartbeat timeout is 0.5 s): generous
DROP_S = 1.5  # [s] the line stays down: several retry periods, each attempt failing
RETRY_S = 0.3  # [s] the supervisor's retry period here (1 s in the service)
ROBOT_WATCHDOG_S = 30.0  # [s] longer than the drop: only the supervisor's DISARM can disarm the robot
FRAME_MAX = 64  # [bytes] more than any frame of ours: what a reopened line may start in the middle of
LONG_FLAP_S = 120.0  # [s] of flapping in the slowest test
# [s] the link's heartbeat timeout where the link must stay up (the flood, the late write): a hang
# guard, so a loaded machine keeping the rig's thread from running is no lost link
PATIENT_LINK_S = 5.0


@pytest.fixture
def answering():
    """An armed robot behind a pty that answers as the firmware does, and a link to it."""
    rig = PtyRobot(firmware=Firmware()).start()
    link = RobotLink(rig.by_id, heartbeat_timeout=PATIENT_LINK_S)
    link.connect()
    link.arm()
    yield rig, link
    link.close()
    rig.stop()


def _delta(after: dict, before: dict) -> dict:
    return {name: after[name] - before[name] for name in after}


def test_a_garbage_flood_is_counted_changes_nothing_and_lets_the_estop_through(answering, patient_estop):
    rig, link = answering
    before, seen = link.counters(), len(link.transitions)
    flood = rig.flood()
    wait_for(lambda: flood.bursts >= FLOOD_BURSTS, f"{FLOOD_BURSTS} bursts of line noise")
    assert link.state == LinkState.ARMED and link.telemetry.state == RobotState.ARMED, "forged frames changed nothing"
    assert rig.firmware.state == RobotState.ARMED, "the heartbeats got through: the robot's watchdog is content"
    stopped = link.estop()
    assert stopped.acknowledged, f"the e-stop was not acknowledged during the flood: {stopped}"
    wait_for(lambda: flood.bursts >= 2 * FLOOD_BURSTS, "as many bursts again, e-stopped")
    rig.stop_flood()
    wait_for(
        lambda: link.counters()["garbage_bytes"] - before["garbage_bytes"] == flood.garbage_bytes,
        f"the link read the whole flood ({flood.bytes} bytes)",
    )
    counted = _delta(link.counters(), before)
    sent = {name: getattr(flood, name) for name in ("garbage_bytes", "bad_checksum", "bad_length", "truncated")}
    sent |= {"rejected_payloads": flood.rejected_payloads, "foreign_frames": flood.foreign_frames}
    assert {name: counted[name] for name in sent} == sent, (counted, flood)
    assert counted["frames_in"] >= flood.good_frames + flood.rejected_payloads + flood.foreign_frames
    assert counted["write_timeouts"] == counted["estops_unacknowledged"] == 0
    moves = [(t.before, t.after) for t in link.transitions[seen:]]
    assert moves == [(LinkState.ARMED, LinkState.ESTOPPED)], f"only the e-stop moved the link: {moves}"
    assert link.state == LinkState.ESTOPPED and rig.firmware.state == RobotState.ESTOPPED
    print(f"flood: {flood.bytes} bytes in {flood.seconds:.1f} s; e-stop acknowledged in {stopped.latency * 1e3:.1f} ms")


def _drop(rig: PtyRobot, how: str) -> None:
    (rig.go_silent if how == "out of range" else rig.hang_up)()


def _restore(rig: PtyRobot, how: str) -> None:
    (rig.resume if how == "out of range" else rig.plug_in)()


@pytest.mark.realtime  # waits on the supervisor's retry period and the line's drop: wall-clock timing
@pytest.mark.parametrize("how", ["out of range", "unplugged"])
def test_a_dropped_line_is_reconnected_once_and_the_robot_disarmed(how, monkeypatch, caplog, thread_errors):
    """Out of range: silence both ways on the same pty; unplugged: the pty and its by-id link gone,
    then a new pty behind the same link. The robot stays armed meanwhile (its watchdog outlasts
    the drop), so only the supervisor's DISARM on reconnecting disarms it."""
    caplog.set_level(logging.DEBUG, logger="parkourlab.robot")
    calls = LinkCalls(monkeypatch)
    rig = PtyRobot(firmware=Firmware(heartbeat_timeout=ROBOT_WATCHDOG_S)).start()
    supervisor = LinkSupervisor(retry_period=RETRY_S)
    link = RobotLink(rig.by_id, heartbeat_timeout=0.5)
    try:
        assert answer_within(ANSWER_BOUND_S, supervisor.connect, link) == LinkState.DISARMED
        link.arm()
        _drop(rig, how)
        wait_for(lambda: link.state == LinkState.DISCONNECTED, "the link sees the line drop", LOST_WITHIN_S)
        time.sleep(DROP_S)
        assert supervisor.reconnects == 0 and rig.firmware.state == RobotState.ARMED
        restored = time.monotonic()
        _restore(rig, how)
        wait_for(lambda: supervisor.reconnects == 1, "the supervisor reconnects")
        wait_for(lambda: rig.firmware.state == RobotState.DISARMED, "the robot disarmed")
        connects = calls.connects
        time.sleep(3 * RETRY_S)  # no further attempt: the link is up
        assert supervisor.reconnects == 1 and calls.connects == connects, "one reconnect, then no more attempts"
        failed = connects - 2  # the first connect and the reconnect aside
        assert failed >= 2, f"the attempts while the line was down failed and were retried: {failed}"
        assert calls.most_connecting == 1 and calls.callers == {"robot-link-supervisor"}, calls.callers
        # The safety property, not one frame sequence: the robot ends disarmed, and after the line came
        # back it got at least one DISARM and no other command (heartbeats aside: the rig does not keep
        # them). A DISARM resent before its acknowledgement is as safe (a loaded machine read
        # [DISARM, DISARM], 5 of 5, beside another service with a pty robot); an ARM, a START or a
        # SET_LEG fails this.
        sent = rig.commands(since=restored)
        assert Kind.DISARM in sent and set(sent) == {Kind.DISARM}, f"the reconnect sent DISARM, nothing else: {sent}"
        assert rig.firmware.state == RobotState.DISARMED, "the robot ends disarmed"
        assert link.state == LinkState.DISARMED and link.telemetry.state == RobotState.DISARMED
        reasons = [t.reason for t in link.transitions if t.after == LinkState.DISCONNECTED]
        expected = "no heartbeat" if how == "out of range" else "read failed"
        assert reasons and reasons[0].startswith(expected), reasons
        counters = link.counters()  # the parser's since the reconnect, the rest since the link was made
        for name in ("bad_checksum", "truncated", "bad_length", "rejected_payloads", "foreign_frames",
                     "write_timeouts", "estops_unacknowledged"):  # fmt: skip
            assert counters[name] == 0, (name, counters)
        assert counters["frames_in"] > 0 and counters["garbage_bytes"] < FRAME_MAX, counters
        assert link_threads() == ["robot-link-heartbeat", "robot-link-reader", "robot-link-supervisor"]
    finally:
        answer_within(ANSWER_BOUND_S, supervisor.close)
        rig.stop()
    assert link_threads() == []
    errors = [r for r in caplog.records if r.levelno >= logging.WARNING or r.exc_info]
    assert errors == [] and thread_errors == [], (errors, thread_errors)


def test_a_write_that_went_out_is_not_a_jammed_line(answering, monkeypatch):
    """Each write on the link's fd goes out whole at once, then the writing thread is kept from
    running for 1.5 x WRITE_TIMEOUT — as the OS or the GIL keep a thread of a busy service waiting.
    pyserial's bounded write called that a jammed line (it checks its timeout after the bytes have
    gone), and an ARM the robot had received was reported as failed."""
    rig, link = answering
    link.disarm()
    fd, write = link.port.serial.fd, os.write

    def late_after_write(target: int, data) -> int:
        written = write(target, data)
        if target == fd:
            time.sleep(WRITE_TIMEOUT * 1.5)
        return written

    monkeypatch.setattr(os, "write", late_after_write)
    try:
        link.arm()  # nothing blocks: the frame is on the line at once
    finally:
        monkeypatch.undo()
    wait_for(lambda: rig.firmware.state == RobotState.ARMED, "the robot received the ARM and armed")
    assert link.counters()["write_timeouts"] == 0


@pytest.mark.slow
def test_a_link_flapping_for_2_min_leaves_no_threads_and_logs_no_errors(monkeypatch, caplog, thread_errors):
    seen = flap_supervised(LONG_FLAP_S, monkeypatch, caplog, thread_errors, seed=13)
    assert set(seen["phases"]) == set(Radio.PHASES) and seen["reconnects"] >= 10, seen
    print(
        f"2 min flapping: {len(seen['phases'])} phases, {seen['connects']} connects, {seen['reconnects']} reconnects;"
        f" threads: baseline {seen['baseline']}, at most {seen['most']} while flapping, {seen['after']} after"
    )
