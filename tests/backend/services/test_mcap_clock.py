"""The one clock of a recording, the tracker's (backend/services/mcap_clock.py): Unix times carried
onto it, and tracker times placed from the run's start. Values worked by hand."""

import datetime

import pytest

from backend.services.mcap_clock import NS_PER_S, TrackerClock, utc_ns

START = datetime.datetime(2026, 3, 1, 12, 0, 0, 250_000)  # naive, as SQLite gives it back: UTC
START_S = 1772366400.25  # the same, Unix time [s]
FIRST_FRAME = 1000.0  # [s] the tracker's time of the run's first frame
LAG = 0.37  # tracker seconds per Unix second
ABS_S = 1e-6  # [s] Unix times near 1.8e9 s hold about 0.2 us in a float64


def lagging(pairs: int = 5) -> TrackerClock:
    """A clock whose records were stamped while the tracker ran at LAG times real time, the first
    0.1 s after the start, then one a second."""
    records = [{"time": START_S + 0.1 + k, "tracker_time": FIRST_FRAME + LAG * (0.1 + k)} for k in range(pairs)]
    return TrackerClock.of(records, START, FIRST_FRAME)


def test_a_stored_time_is_exact_utc_nanoseconds():
    assert utc_ns(START) == utc_ns(START.replace(tzinfo=datetime.UTC)) == 1_772_366_400_250_000_000
    assert utc_ns(START) == round(START.replace(tzinfo=datetime.UTC).timestamp() * 1e6) * 1000


def test_tracker_times_are_placed_from_the_run_s_start():
    clock = lagging()
    assert clock.log_time(FIRST_FRAME) == utc_ns(START), "the first frame at the start"
    assert clock.log_time(FIRST_FRAME + 31.0) == utc_ns(START) + 31 * NS_PER_S


def test_between_stamp_pairs_a_unix_time_is_interpolated():
    clock = lagging()
    assert clock.tracker_time(START_S + 0.1 + 2.5) == pytest.approx(FIRST_FRAME + LAG * 2.6, abs=ABS_S)
    assert clock.tracker_time(START_S + 3.1) == pytest.approx(FIRST_FRAME + LAG * 3.1, abs=ABS_S), "on a pair"


def test_beyond_the_pairs_a_unix_second_is_a_tracker_second():
    clock = lagging()
    last = FIRST_FRAME + LAG * 4.1
    assert clock.tracker_time(START_S + 4.1 + 2.0) == pytest.approx(last + 2.0, abs=ABS_S)
    assert clock.tracker_time(START_S) == pytest.approx(FIRST_FRAME + LAG * 0.1 - 0.1, abs=ABS_S)


def test_without_pairs_the_run_s_start_is_the_first_frame():
    """Runs stored before commands and telemetry carried tracker_time: each at its own Unix time."""
    clock = TrackerClock.of(
        [{"time": START_S + 2.0, "tracker_time": None}, {"time": START_S + 3.0}], START, FIRST_FRAME
    )
    assert clock.tracker_time(START_S + 2.0) == pytest.approx(FIRST_FRAME + 2.0, abs=ABS_S)
    assert clock.record_time({"time": START_S + 2.0}) == pytest.approx(utc_ns(START) + 2 * NS_PER_S, abs=1000)


def test_a_record_s_own_tracker_time_wins_over_its_unix_time():
    clock = lagging()
    record = {"time": START_S + 31.0, "tracker_time": FIRST_FRAME + 11.5}
    assert clock.record_time(record) == utc_ns(START) + 11_500_000_000
    assert clock.record_time({"time": START_S + 2.1}) == pytest.approx(
        clock.log_time(FIRST_FRAME + LAG * 2.1), abs=1000
    )


def test_the_tracker_s_time_never_goes_back():
    """Pairs out of order (a stamp taken late) cannot place a later Unix time earlier on the tracker."""
    records = [{"time": START_S + 1.0, "tracker_time": 1001.0}, {"time": START_S + 2.0, "tracker_time": 1000.5},
               {"time": START_S + 3.0, "tracker_time": 1003.0}]  # fmt: skip
    clock = TrackerClock.of(records, START, FIRST_FRAME)
    assert list(clock.tracker) == [1001.0, 1001.0, 1003.0]
    placed = [clock.tracker_time(START_S + 1.0 + 0.25 * k) for k in range(9)]
    assert placed == sorted(placed)
