"""The e-stop latch: held from the press until a RESET is acknowledged, kept across restarts."""

import json

from backend.robot.latch import EstopLatch, LatchState


def test_a_press_holds_until_released_whatever_the_connections_do():
    latch = EstopLatch()
    assert latch.state == LatchState() and not latch.held
    latch.engage()
    assert latch.state.pending and latch.state.since is not None
    latch.acknowledged()
    assert latch.held and not latch.state.pending, "acknowledged: held, no longer sent"
    latch.unconfirmed()  # a new connection: the robot must confirm it again
    assert latch.state.pending
    latch.release()
    assert latch.state == LatchState()


def test_acknowledging_or_reconnecting_a_released_latch_changes_nothing():
    latch = EstopLatch()
    latch.acknowledged()
    latch.unconfirmed()
    assert latch.state == LatchState()


def test_a_held_latch_survives_a_restart_and_a_release_too(tmp_path):
    path = tmp_path / "estop-latch.json"
    latch = EstopLatch(path)
    latch.engage()
    latch.flush()
    restarted = EstopLatch(path)
    assert restarted.held and restarted.state.pending, "a restart finds it held, to be confirmed by the robot"
    restarted.release()
    restarted.flush()
    assert not EstopLatch(path).held
    assert not (tmp_path / "estop-latch.json.tmp").exists(), "written whole, then renamed"


def test_who_pressed_it_and_who_reset_it_survive_a_restart(tmp_path):
    path = tmp_path / "estop-latch.json"
    latch = EstopLatch(path)
    latch.engage()
    latch.attribute("someone at 10.0.0.7")
    latch.flush()
    assert EstopLatch(path).state.pressed_by == "someone at 10.0.0.7"
    latch.release()
    latch.reset_by("ada")
    latch.flush()
    restarted = EstopLatch(path).state
    assert not restarted.held and restarted.pressed_by is None
    assert restarted.reset_by == "ada" and restarted.reset_at is not None
    latch.reset_by("bob")  # a reset of a released latch: still who last reset it
    latch.engage()  # pressed again: whoever presses it now is named by the service
    latch.reset_by("eve")  # a reset that has not released it names nobody
    latch.flush()
    assert EstopLatch(path).state.held and EstopLatch(path).state.reset_by is None


def test_a_latch_file_that_cannot_be_read_holds(tmp_path):
    path = tmp_path / "estop-latch.json"
    for text in ("{", json.dumps({"held": "no"}), json.dumps([1]), json.dumps({"since": 3.0})):
        path.write_text(text)
        latch = EstopLatch(path)
        assert latch.held and "until a reset" in latch.state.reason(), text


def test_the_reason_says_whether_the_robot_confirmed_it():
    latch = EstopLatch()
    assert latch.state.reason() is None
    latch.engage()
    assert "not yet acknowledged" in latch.state.reason()
    latch.acknowledged()
    assert "the robot acknowledged it" in latch.state.reason()


def test_changes_reach_the_file_in_their_order(tmp_path):
    path = tmp_path / "estop-latch.json"
    latch = EstopLatch(path)
    for _ in range(20):
        latch.engage()
        latch.release()
    latch.engage()
    latch.flush()
    assert json.loads(path.read_text())["held"] is True


def test_a_change_is_durable_only_once_its_file_is_written(tmp_path, monkeypatch):
    """The press never waits for the disk, and says when the file has it: a slow disk is held up
    here until the test lets it write."""
    import threading

    path = tmp_path / "estop-latch.json"
    latch = EstopLatch(path)
    disk = threading.Event()
    write = latch._write
    monkeypatch.setattr(latch, "_write", lambda *args: (disk.wait(5), write(*args)))
    latch.engage()  # returns at once
    assert latch.held and not latch.state.durable and not path.exists()
    assert latch.flush(timeout=0.05) is False, "not on disk yet"
    disk.set()
    assert latch.flush() is True and latch.state.durable
    assert json.loads(path.read_text())["held"] is True


def test_a_write_that_fails_leaves_it_held_not_durable_and_says_why(tmp_path):
    latch = EstopLatch(tmp_path / "no-such-folder" / "estop-latch.json")
    latch.engage()
    assert latch.flush() is False and latch.held and not latch.state.durable
    assert "could not save the e-stop latch" in latch.save_error


def test_a_latch_kept_in_memory_is_durable_at_once():
    latch = EstopLatch()
    latch.engage()
    assert latch.state.durable and latch.flush(timeout=1) is True
