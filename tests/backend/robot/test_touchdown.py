"""Touchdowns from tracker poses (backend/robot/touchdown.py): against the simulator's own climb, with
tracker noise and lost frames, and against flights whose touchdown is known in closed form."""

import json
import math

import numpy as np
import pytest

from backend.robot.touchdown import MIN_FIT_POSES, Touchdown, detect_touchdowns, height_gains, scan_touchdowns
from sim_core import ControlSchedule, LegControl, get_preset
from sim_core.model.walls import Wall

PAPER = get_preset("paper")
LEG = LegControl.from_degrees(30.0, 0.9)
RTOL_FIT = 1e-9  # a least-squares fit through exact straight-line and parabola samples
DT = 0.01  # [s] the camera's 100 Hz
X_START, VX, Y0, VY0 = 0.005, 1.5, 0.3, 0.8  # [m, m/s] a flight from just left of the centre line


def _detect(robot, schedule, t, x, y):
    return detect_touchdowns(t, x, y, robot, lambda k: schedule[k + 1])


def test_touchdowns_match_the_simulator(climb):
    robot, schedule, path, si = climb
    found = _detect(robot, schedule, si.time, si.x, si.y)
    assert len(found) == 12
    np.testing.assert_allclose([td.time for td in found], si.touchdown_times[1:13], atol=1e-4)
    np.testing.assert_allclose([td.state for td in found], path.section_states[1:13], atol=1e-4)
    np.testing.assert_allclose(height_gains(found, robot), path.rises[1:12], atol=1e-4)
    assert [td.wall for td in found] == [1, -1] * 6


def test_touchdowns_survive_tracker_noise_and_dropped_frames(climb):
    robot, schedule, path, si = climb
    rng = np.random.default_rng(1)
    keep = rng.random(si.time.size) > 0.1  # 10% of frames lost
    noise = 0.001  # 1 mm
    x = si.x[keep] + rng.normal(0, noise, keep.sum())
    y = si.y[keep] + rng.normal(0, noise, keep.sum())
    found = _detect(robot, schedule, si.time[keep], x, y)
    assert len(found) == 12
    np.testing.assert_allclose([td.state for td in found], path.section_states[1:13], atol=0.03)
    np.testing.assert_allclose(height_gains(found, robot), path.rises[1:12], atol=0.02)


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_a_stream_scanned_as_it_grows_gives_the_touchdowns_of_one_scan(climb, seed):
    """A live run scans only the poses since its last scan's resume point (and a few before, for the
    pitch): in chunks of any size, the touchdowns are exactly those of one scan of the whole, even
    where the pitch is missing (NaN) for a few poses and must be looked back for."""
    robot, schedule, _path, si = climb
    rng = np.random.default_rng(seed)
    x = si.x + rng.normal(0, 0.001, si.x.size)
    pitch = rng.normal(0, np.radians(2.0), si.x.size)
    pitch[rng.random(si.x.size) < 0.2] = np.nan
    whole = detect_touchdowns(si.time, x, si.y, robot, lambda k: schedule[k + 1], pitch)
    assert len(whole) >= 10
    found, scan_from, end = [], 1, 0
    while end < si.time.size:
        end = min(si.time.size, end + int(rng.integers(1, 60)))
        first = max(0, scan_from - 11)  # as the live run asks the tracker: PITCH_LOOKBACK + 1 before
        window = slice(first, end)
        scan = scan_touchdowns(si.time[window], x[window], si.y[window], robot, lambda k: schedule[k + 1],
                               pitch[window], start=scan_from - first, first_index=len(found))  # fmt: skip
        found += scan.touchdowns
        scan_from = first + scan.resume
    assert found == whole


def _flight(wall: Wall, vx: float = VX, pitch: float = 0.0, samples: int = 30):
    """A ballistic flight from the centre line toward ``wall``, sampled at 100 Hz in wall coordinates
    (SI), and where the touchdown on it is: (time, body height, foot height, section state)."""
    t = DT * np.arange(samples)
    x = wall * (-X_START + vx * t)
    y = Y0 + VY0 * t - 0.5 * PAPER.gravity * t**2
    psi = LEG.psi0 - wall * pitch  # the leg turned with the body
    reach = LEG.zeta0 * PAPER.leg_length
    crossing = (0.5 * PAPER.wall_distance - reach * math.cos(psi) + X_START) / vx
    body = Y0 + VY0 * crossing - 0.5 * PAPER.gravity * crossing**2
    state = (-vx / PAPER.scales.velocity, (VY0 - PAPER.gravity * crossing) / PAPER.scales.velocity)
    return t, x, y, (crossing, body, body - reach * math.sin(psi), state)


@pytest.mark.parametrize("wall", [Wall.RIGHT, Wall.LEFT])
def test_a_flight_gives_its_touchdown_in_closed_form(wall):
    """Either wall: the state comes out flipped to the left wall, the same for mirrored flights."""
    t, x, y, (crossing, body, foot, state) = _flight(wall)
    [found] = detect_touchdowns(t, x, y, PAPER, lambda _k: LEG)
    assert (found.index, found.wall) == (0, wall)
    assert found.time == pytest.approx(crossing, rel=RTOL_FIT)
    assert found.body_height == pytest.approx(body, rel=RTOL_FIT)
    assert found.foot_height == pytest.approx(foot, rel=RTOL_FIT)
    assert found.state == pytest.approx(state, rel=RTOL_FIT)
    assert found.poses_fitted == np.sum((t > 0) & (t < crossing)), "the flight's poses: centre line to touchdown"


def test_the_bodys_pitch_turns_the_leg():
    pitch = 0.2  # [rad] on the right wall the leg turns toward the horizontal: it reaches farther
    t, x, y, (crossing, _body, foot, _state) = _flight(Wall.RIGHT, pitch=pitch)
    [found] = detect_touchdowns(t, x, y, PAPER, lambda _k: LEG, np.full(t.size, pitch))
    assert found.time == pytest.approx(crossing, rel=RTOL_FIT)
    assert found.foot_height == pytest.approx(foot, rel=RTOL_FIT)
    [level] = detect_touchdowns(t, x, y, PAPER, lambda _k: LEG)
    assert found.time < level.time and found.foot_height > level.foot_height, "sooner and higher than unpitched"


def test_a_pose_without_a_pitch_takes_the_newest_one_before_it():
    t, x, y, _touchdown = _flight(Wall.RIGHT)
    pitch = np.full(t.size, 0.2)
    gaps = pitch.copy()
    gaps[3::2] = math.nan  # the markers gave no pitch in every other frame
    assert detect_touchdowns(t, x, y, PAPER, lambda _k: LEG, gaps) == detect_touchdowns(
        t, x, y, PAPER, lambda _k: LEG, pitch
    )
    none = np.full(t.size, math.nan)
    assert detect_touchdowns(t, x, y, PAPER, lambda _k: LEG, none) == detect_touchdowns(
        t, x, y, PAPER, lambda _k: LEG
    ), "no pitch known at all: the leg as commanded"


def test_a_flight_too_short_to_fit_is_skipped():
    fast = 4.0  # [m/s] the body reaches the leg's line in fewer than MIN_FIT_POSES frames
    t, x, y, (crossing, *_rest) = _flight(Wall.RIGHT, vx=fast)
    assert np.sum((t > 0) & (t < crossing)) < MIN_FIT_POSES
    assert detect_touchdowns(t, x, y, PAPER, lambda _k: LEG) == []


def test_each_touchdown_gets_its_own_controls():
    """Touchdown k is measured with ``leg_for(k)``: a longer leg meets the wall sooner."""
    t, x, y, _touchdown = _flight(Wall.RIGHT)
    back = _flight(Wall.LEFT)
    t2 = np.concatenate([t, t[-1] + DT + back[0]])
    x2, y2 = np.concatenate([x, back[1]]), np.concatenate([y, back[2]])
    asked = []

    def leg_for(k: int) -> LegControl:
        asked.append(k)
        return LegControl.from_degrees(30.0, (0.9, 0.8)[k])

    first, second = detect_touchdowns(t2, x2, y2, PAPER, leg_for)
    assert (first.wall, second.wall, second.index) == (Wall.RIGHT, Wall.LEFT, 1)
    assert set(asked) == {0, 1}
    assert second.time - (t[-1] + DT) > first.time, "the shorter leg of touchdown 1 meets its wall later"


def test_height_gains_are_the_feet_rising_in_leg_lengths():
    feet = [0.10, 0.16, 0.13]
    touchdowns = [Touchdown(k, float(k), Wall.RIGHT, (-0.9, -0.2), 0.0, h, 6) for k, h in enumerate(feet)]
    np.testing.assert_allclose(height_gains(touchdowns, PAPER), np.diff(feet) / PAPER.leg_length, rtol=1e-12)


def test_a_touchdown_is_stored_as_json_and_read_back_whole():
    touchdown = Touchdown(3, 12.5, Wall.LEFT, (-0.93, -0.17), 0.41, 0.25, 7)
    stored = json.loads(json.dumps(touchdown.to_dict()))
    assert stored["wall"] == -1 and stored["state"] == [-0.93, -0.17]
    back = Touchdown.from_dict(stored)
    assert back == touchdown and back.wall is Wall.LEFT


@pytest.mark.parametrize("name", ["narrowing", "staircase"])
def test_in_a_world_a_touchdown_is_where_the_foot_meets_its_side(name):
    """The world's own climb (sim_core's), sampled at 100 Hz: the touchdowns are found where the
    foot meets the sides at its height; read as parallel walls, the leaning sides' are not."""
    from sim_core.planning.launch import start_velocity
    from sim_core.world.geometry import pack, side_x
    from sim_core.world.named import named_world
    from sim_core.world.trajectory import simulate_world_trajectory

    model, metres, scales = PAPER.to_model(), PAPER.leg_length, PAPER.scales
    world = named_world(name, model.d_hat)
    schedule = ControlSchedule.from_degrees([(30.0, 0.9), (30.0, 0.9)])
    path, climb = simulate_world_trajectory(model, world, schedule, start_velocity(model), 8,
                                            sample_rate=100.0 * scales.time)  # fmt: skip
    sides = pack(world, model.mu)

    def side_at(wall, height_m):
        return float(side_x(sides, 0 if wall == Wall.LEFT else 1, height_m / metres)) * metres

    t, x, y = path.time * scales.time, path.x * metres, path.y * metres
    found = detect_touchdowns(t, x, y, PAPER, lambda k: schedule[k + 1], side_at=side_at)
    # The path ends at the last touchdown (no pose past its line), or goes on falling after a slip.
    touched = min(len(found), len(climb.states) - 1)
    assert touched >= max(4, len(climb.states) - 2)
    np.testing.assert_allclose([(td.body_x, td.body_height) for td in found[:touched]],
                               climb.states[1 : touched + 1, :2] * metres, atol=1e-3)  # fmt: skip
    if name == "narrowing":
        parallel = detect_touchdowns(t, x, y, PAPER, lambda k: schedule[k + 1])
        seen = [td.body_x for td in parallel[:touched]]
        assert not np.allclose(seen, climb.states[1 : len(seen) + 1, 0] * metres, atol=1e-3)
