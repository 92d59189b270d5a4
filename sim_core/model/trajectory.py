"""Full trajectories in wall coordinates, for display and for comparison with the robot.

The Poincaré map works in the flipped frame (every stance on the left wall). Here the flips
are undone jump by jump (docs/model.md §2): jump 0's stance is on the left wall, jump 1's on the
right, and so on. Stance is sampled by cubic Hermite interpolation between the integrator's
own steps (positions and rates are both known there, error ~1e-6 l0); flight is closed form.

Columns (all arrays of one length, see :attr:`Trajectory.COLUMNS`): time, body ``x, y``, foot
``foot_x, foot_y`` (during flight: where the next leg's foot is), leg angle ``psi`` [rad] and
length ``zeta`` of the leg drawn, ``phase`` (0 stance, 1 flight), and the ``jump`` index.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from sim_core.model import stride
from sim_core.model.controls import ControlSchedule
from sim_core.model.failures import OK, Failure
from sim_core.model.integrate import PSI, PSI_DOT, STATE_SIZE, TIME, ZETA, ZETA_DOT
from sim_core.model.params import ModelParams, PhysicalParams
from sim_core.model.poincare import check_jumps, check_section_state
from sim_core.model.validation import check_range
from sim_core.model.walls import wall_of

STANCE = 0
FLIGHT = 1
MAX_STANCE_NODES = 20_000
DEFAULT_SAMPLE_RATE = 200.0  # samples per sqrt(l0/g)


@dataclass(frozen=True)
class Trajectory:
    """A sampled path plus the events of the run.

    Attributes:
        time, x, y, foot_x, foot_y, psi, zeta, phase, jump: sampled columns (see module doc).
        touchdown_times: time of each touchdown, starting with 0 for the first.
        section_states: shape (k + 1, 2), section states at those touchdowns (flipped frame).
        rises: shape (k,), height gain per completed jump.
        failure: why the run ended early, or None; failed_jump is 1-based.
        units: ``"nondimensional"`` (l0, sqrt(l0/g)) or ``"SI"`` (m, s).
    """

    time: np.ndarray
    x: np.ndarray
    y: np.ndarray
    foot_x: np.ndarray
    foot_y: np.ndarray
    psi: np.ndarray
    zeta: np.ndarray
    phase: np.ndarray
    jump: np.ndarray
    touchdown_times: np.ndarray
    section_states: np.ndarray
    rises: np.ndarray
    failure: Failure | None
    failed_jump: int | None
    units: str = "nondimensional"

    COLUMNS = ("time", "x", "y", "foot_x", "foot_y", "psi", "zeta", "phase", "jump")

    def columns(self) -> dict[str, np.ndarray]:
        return {name: getattr(self, name) for name in self.COLUMNS}

    def to_si(self, robot: PhysicalParams) -> Trajectory:
        """The same trajectory in metres and seconds (velocities in m/s, angles unchanged)."""
        if self.units == "SI":
            return self
        scales = robot.scales
        return replace(
            self,
            time=self.time * scales.time,
            x=self.x * scales.length,
            y=self.y * scales.length,
            foot_x=self.foot_x * scales.length,
            foot_y=self.foot_y * scales.length,
            zeta=self.zeta * scales.length,
            touchdown_times=self.touchdown_times * scales.time,
            section_states=self.section_states * scales.velocity,
            rises=self.rises * scales.length,
            units="SI",
        )


def simulate_trajectory(
    model: ModelParams,
    schedule: ControlSchedule,
    state,
    jumps: int,
    *,
    sample_rate: float = DEFAULT_SAMPLE_RATE,
    start_height: float = 0.0,
) -> Trajectory:
    """Simulate ``jumps`` jumps from section state ``state`` and sample the path.

    Args:
        state: ``(xdot, ydot)`` at the first touchdown, on the left wall.
        sample_rate: samples per unit of nondimensional time ``sqrt(l0/g)``.
        start_height: body height at the first touchdown [l0].
    """
    section = check_section_state(state)
    jumps = check_jumps(jumps)
    check_range("sample_rate", sample_rate, 0.0, 1e6, high_open=False)
    check_range("start_height", start_height)
    parameters = model.record()
    half_width = 0.5 * model.d_hat
    record = np.empty((MAX_STANCE_NODES, STATE_SIZE))
    pieces: list[dict[str, np.ndarray]] = []
    sections = [section.copy()]
    rises: list[float] = []
    touchdown_times = [0.0]
    failure = None
    clock = 0.0
    foot_height = start_height - schedule[0].zeta0 * math.sin(schedule[0].psi0)
    xdot, ydot = section
    for k in range(jumps):
        leg, next_leg = schedule[k], schedule[k + 1]
        side = -float(wall_of(k))  # the flipped frame's sign: +1 for a stance on the left wall (x = -d/2)
        status, next_xdot, next_ydot, rise, stance_time, flight_time, rows = stride.jump(
            xdot, ydot, leg.psi0, leg.zeta0, next_leg.psi0, next_leg.zeta0, parameters, record
        )
        if rows >= 2:
            pieces.append(stance_piece(record[:rows], clock, sample_rate, side, -half_width, foot_height, k))
        if status != OK:
            failure = Failure(status)
            break
        pieces.append(
            flight_piece(record[rows - 1], clock, flight_time, sample_rate, side, -half_width, foot_height, next_leg, k)
        )
        clock += stance_time + flight_time
        foot_height += rise
        xdot, ydot = next_xdot, next_ydot
        sections.append(np.array([xdot, ydot]))
        rises.append(rise)
        touchdown_times.append(clock)
    columns = joined_columns(pieces)
    return Trajectory(
        **columns,
        touchdown_times=np.array(touchdown_times),
        section_states=np.array(sections),
        rises=np.array(rises),
        failure=failure,
        failed_jump=len(rises) + 1 if failure is not None else None,
    )


def joined_columns(pieces: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    """The :attr:`Trajectory.COLUMNS` of sampled pieces (stances and flights) one after another;
    empty columns for none (a touchdown that slipped at once)."""
    return {
        name: np.concatenate([piece[name] for piece in pieces]) if pieces else np.empty(0)
        for name in Trajectory.COLUMNS
    }


def _sample_times(start: float, duration: float, rate: float) -> np.ndarray:
    """Global sample times ``i / rate`` in ``[start, start + duration)``."""
    first = math.ceil(start * rate - 1e-9)
    last = math.ceil((start + duration) * rate - 1e-9)
    return np.arange(first, last) / rate


def stance_piece(nodes, clock, rate, side, foot_x, foot_height, jump_index):
    """Samples of one stance from its integrator ``nodes`` (rows of the state), its foot at
    ``(foot_x, foot_height)`` in the flipped frame (``-d_hat/2`` on parallel walls) and ``side``
    the flipped frame's sign (+1: the stance is on the left wall), from time ``clock``."""
    from scipy.interpolate import CubicHermiteSpline  # half a second to import: loaded when first sampled

    times = _sample_times(clock, nodes[-1, TIME], rate)
    local = np.clip(times - clock, 0.0, nodes[-1, TIME])
    zeta = CubicHermiteSpline(nodes[:, TIME], nodes[:, ZETA], nodes[:, ZETA_DOT])(local)
    psi = CubicHermiteSpline(nodes[:, TIME], nodes[:, PSI], nodes[:, PSI_DOT])(local)
    return _piece(
        times,
        x=side * (foot_x + zeta * np.cos(psi)),
        y=foot_height + zeta * np.sin(psi),
        foot_x=np.full_like(times, side * foot_x),
        foot_y=np.full_like(times, foot_height),
        psi=psi,
        zeta=zeta,
        phase=STANCE,
        jump_index=jump_index,
    )


def flight_piece(liftoff, clock, flight_time, rate, side, foot_x, foot_height, next_leg, jump_index):
    """Samples of the flight after the stance whose last node is ``liftoff`` (foot, side and clock
    as :func:`stance_piece`), ``flight_time`` long, the next leg held at its controls."""
    psi, zeta_dot, psi_dot = liftoff[PSI], liftoff[ZETA_DOT], liftoff[PSI_DOT]
    start = clock + liftoff[TIME]
    times = _sample_times(start, flight_time, rate)
    local = times - start
    xdot, ydot = stride.liftoff_velocity(psi, zeta_dot, psi_dot)
    x_flipped = foot_x + math.cos(psi) + xdot * local
    y = foot_height + math.sin(psi) + ydot * local - 0.5 * local**2
    x = side * x_flipped
    return _piece(
        times,
        x=x,
        y=y,
        foot_x=x + side * next_leg.zeta0 * math.cos(next_leg.psi0),
        foot_y=y - next_leg.zeta0 * math.sin(next_leg.psi0),
        psi=np.full_like(times, next_leg.psi0),
        zeta=np.full_like(times, next_leg.zeta0),
        phase=FLIGHT,
        jump_index=jump_index,
    )


def _piece(times, *, x, y, foot_x, foot_y, psi, zeta, phase, jump_index):
    return {
        "time": times,
        "x": x,
        "y": y,
        "foot_x": foot_x,
        "foot_y": foot_y,
        "psi": psi,
        "zeta": zeta,
        "phase": np.full(times.shape, phase, dtype=np.int8),
        "jump": np.full(times.shape, jump_index, dtype=np.int64),
    }
