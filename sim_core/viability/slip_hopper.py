"""sheim/vibly's SLIP hopper as a compiled step map, to cross-check the viability engine.

This reproduces ``models/slip.py`` of sheim/vibly (Heim & Spröwitz, the reference implementation of
viability kernels) equation for equation, so that :mod:`sim_core.viability.engine` can be checked against
vibly's own kernel of the same model (``scripts/vibly_crosscheck.py``). It is no part of the
ParkourBot's model.

Model: a point mass ``m`` on a massless linear spring leg (stiffness ``k``, rest length ``l0``) in
the sagittal plane, under gravity ``g``; conservative, so the total energy ``E`` is fixed. One step
runs apex -> flight -> touchdown -> stance -> liftoff -> flight -> apex:

* the leg is held at the angle of attack ``aoa`` from the vertical in flight (foot ahead of the
  hip for ``aoa > 0``) and touches down when the foot reaches the ground;
* in stance the foot is pinned; the leg force is ``k (l0 - l)`` along the leg (bilateral, as in
  vibly); liftoff is the leg passing back through ``l0`` while extending;
* flight is ballistic, in closed form.

State and action (vibly's ``xp2s`` / ``s2x`` / ``sa2xp``): the state is the *normalised apex
height* ``s = m g y / (m g y + m xdot^2 / 2)`` [-], in [0, 1] at the fixed energy ``E``; the action
is ``aoa`` [rad].

Failures (vibly's events and ``check_failure``): the foot starting below the ground
(``infeasible``), the body reaching the ground in flight or stance (``fall``), the body running
backwards in stance (``xdot < -1e-5`` m/s: ``reversal``), a liftoff heading down with no apex
before the ground (``no_apex``), an apex reached with ``xdot <= 0`` (``backward``).

Numerics: stance by fixed-step RK4 (``SlipHopper.stance_step``), each event located by root-finding
(Illinois) on the RK4 step as a function of its length, with scipy's ``solve_ivp`` rules for event
directions; the touchdown state is computed in vibly's floating-point order, since whether a leg
that extends at touchdown lifts off at once depends on the sign of its rounding.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numba import prange

from sim_core._jit import kernel, parallel_kernel
from sim_core.model.validation import check_range

__all__ = ["SlipHopper", "SlipOutcome", "slip_outcomes", "slip_step", "slip_step_map"]

APEX, INFEASIBLE, FALL, REVERSAL, NO_APEX, BACKWARD = range(6)  # kernel codes: SlipOutcome's values
TOUCHED_GROUND, LIFTED_OFF, RAN_BACK = range(3)  # stance events, in vibly's order
REVERSAL_SPEED = 1e-5  # [m/s] vibly's reversal event: xdot + 1e-5 crossing zero downward
ISCLOSE_ATOL = 1e-8  # np.isclose's tolerance, with which vibly compares apex height and ydot with zero
ROOT_ITERATIONS = 100


class SlipOutcome(IntEnum):
    """How one apex-to-apex step ended; ``APEX`` is the only success."""

    APEX = APEX
    INFEASIBLE = INFEASIBLE
    FALL = FALL
    REVERSAL = REVERSAL
    NO_APEX = NO_APEX
    BACKWARD = BACKWARD

    @property
    def message(self) -> str:
        return _MESSAGES[self]


_MESSAGES = {
    SlipOutcome.APEX: "reached the next apex moving forward",
    SlipOutcome.INFEASIBLE: "the foot starts below the ground (apex below l0 cos(aoa)) or s is outside [0, 1]",
    SlipOutcome.FALL: "the body reached the ground",
    SlipOutcome.REVERSAL: "the body ran backwards during stance (xdot < -1e-5 m/s)",
    SlipOutcome.NO_APEX: "lifted off heading down: no apex before the ground",
    SlipOutcome.BACKWARD: "reached the apex standing or moving backwards (xdot <= 0)",
}


@dataclass(frozen=True, slots=True)
class SlipHopper:
    """vibly's SLIP parameters (``demos/computeQ_slip.py``). SI units.

    The total energy is vibly's, from its reference apex ``x0``: height 0.85 m, speed 5.5 m/s.
    """

    mass: float = 80.0  # m [kg]
    stiffness: float = 8200.0  # k [N/m]
    resting_length: float = 1.0  # l0 [m]
    gravity: float = 9.81  # g [m/s^2]
    total_energy: float = 80.0 / 2 * 5.5**2 + 9.81 * 80.0 * 0.85  # E [J], vibly's compute_total_energy(x0)
    stance_step: float = 5e-4  # RK4 step in stance [s]: s' within ~1e-11 of DOP853 at rtol 1e-12
    max_time: float = 5.0  # longest stance [s], vibly's MAX_TIME

    def __post_init__(self):
        for field in ("mass", "stiffness", "resting_length", "gravity", "total_energy", "max_time"):
            check_range(field, getattr(self, field), 0.0)
        check_range("stance_step", self.stance_step, 0.0, 0.01)

    def kernel_args(self) -> tuple[float, ...]:
        return (self.mass, self.stiffness, self.resting_length, self.gravity, self.total_energy,
                self.stance_step, self.max_time)  # fmt: skip


# In the kernels a stance state is ``(x, y, xdot, ydot)`` [m, m/s] of the body and ``leg`` is
# ``(foot_x, foot_y, k / m, l0, g)``, the foot pinned where it touched down.


@kernel
def _rates(state, leg):
    """Stance rates: the leg force per unit mass along the leg, then gravity."""
    x, y, vx, vy = state
    foot_x, foot_y, spring_rate, resting_length, gravity = leg
    length = math.hypot(x - foot_x, y - foot_y)
    along = spring_rate * (resting_length - length) / length
    return vx, vy, along * (x - foot_x), along * (y - foot_y) - gravity


@kernel
def _moved(state, rate, h):
    return state[0] + h * rate[0], state[1] + h * rate[1], state[2] + h * rate[2], state[3] + h * rate[3]


@kernel
def _rk4(state, h, leg):
    """One classical Runge-Kutta step of length ``h`` [s]."""
    a = _rates(state, leg)
    b = _rates(_moved(state, a, 0.5 * h), leg)
    c = _rates(_moved(state, b, 0.5 * h), leg)
    d = _rates(_moved(state, c, h), leg)
    mean = (
        a[0] + 2.0 * (b[0] + c[0]) + d[0],
        a[1] + 2.0 * (b[1] + c[1]) + d[1],
        a[2] + 2.0 * (b[2] + c[2]) + d[2],
        a[3] + 2.0 * (b[3] + c[3]) + d[3],
    )
    return _moved(state, mean, h / 6.0)


@kernel
def _events(state, leg):
    """vibly's stance events: the body's height, the leg's length past rest, xdot + 1e-5 [m/s]."""
    x, y, vx, _ = state
    return y, math.hypot(x - leg[0], y - leg[1]) - leg[3], vx + REVERSAL_SPEED


@kernel
def _crosses(event, before, after):
    """scipy's rule: liftoff counts rising (<= 0 to >= 0), touching ground and running back falling."""
    if event == LIFTED_OFF:
        return before <= 0.0 and after >= 0.0
    return before >= 0.0 and after <= 0.0


@kernel
def _event_time(event, state, h, before, after, leg):
    """The step length in [0, h] [s] at which ``event`` crosses zero (Illinois on the RK4 step)."""
    low, high, f_low, f_high = 0.0, h, before, after
    if f_low == 0.0:
        return 0.0
    side = 0
    for _ in range(ROOT_ITERATIONS):
        if f_high == f_low or high - low <= 4e-16 * h:
            break
        middle = high - f_high * (high - low) / (f_high - f_low)
        if not low < middle < high:
            middle = 0.5 * (low + high)
        f_middle = _events(_rk4(state, middle, leg), leg)[event]
        if f_middle == 0.0:
            return middle
        if (f_middle > 0.0) == (f_high > 0.0):
            high, f_high = middle, f_middle
            if side == 1:  # the same end twice: halve the other's weight (Illinois)
                f_low *= 0.5
            side = 1
        else:
            low, f_low = middle, f_middle
            if side == -1:
                f_high *= 0.5
            side = -1
    return high


@kernel
def _stance(state, leg, stance_step, max_time):
    """Stance from touchdown to the first event: ``(event, state)``, event -1 when ``max_time`` [s]
    passed without one."""
    before = _events(state, leg)
    t = 0.0
    while t < max_time:
        h = min(stance_step, max_time - t)
        stepped = _rk4(state, h, leg)
        after = _events(stepped, leg)
        first, earliest = -1, h
        for event in range(3):
            if _crosses(event, before[event], after[event]):
                when = _event_time(event, state, h, before[event], after[event], leg)
                if first < 0 or when < earliest:
                    first, earliest = event, when
        if first >= 0:
            return first, _rk4(state, earliest, leg)
        state, before = stepped, after
        t += h
    return -1, state


@kernel
def _ground_time(height, gravity):
    """vibly's ``_solve_ballistic_quadratic`` from rest: the fall time [s] from ``height`` [m]."""
    a = -0.5 * gravity
    return (-0.0 - math.sqrt(0.0 * 0.0 - 4.0 * a * height)) / (2.0 * a)


@kernel
def _apex_step(s, aoa, mass, stiffness, resting_length, gravity, energy, stance_step, max_time):
    """One step from the apex of normalised height ``s`` with angle of attack ``aoa`` [rad]:
    ``(outcome, s at the next apex)``, NaN unless the outcome is ``APEX``."""
    if not 0.0 <= s <= 1.0:
        return INFEASIBLE, math.nan
    # vibly's s2x and reset_leg, in its order of operations
    y0 = energy * s / mass / gravity
    vx = math.sqrt(energy * (1.0 - s) / mass * 2.0)
    foot_x = math.sin(aoa) * resting_length
    foot_y0 = y0 - math.cos(aoa) * resting_length
    if foot_y0 < 0.0:
        return INFEASIBLE, math.nan
    t_down = _ground_time(foot_y0, gravity)
    if _ground_time(y0, gravity) <= t_down:
        return FALL, math.nan
    drop = 0.5 * gravity * t_down**2
    foot_x += vx * t_down
    foot_y = foot_y0 - drop
    state = (vx * t_down, y0 - drop, vx, 0.0 - gravity * t_down)
    leg = (foot_x, foot_y, stiffness / mass, resting_length, gravity)
    event, state = _stance(state, leg, stance_step, max_time)
    if event == TOUCHED_GROUND:
        return FALL, math.nan
    if event == RAN_BACK:
        return REVERSAL, math.nan
    _, y, vx, vy = state  # liftoff (or vibly's flight after max_time in stance)
    if vy < 0.0:
        return NO_APEX, math.nan
    rise = vy / gravity if vy > ISCLOSE_ATOL else 0.0
    y_apex = y + vy * rise - 0.5 * gravity * rise**2
    if y_apex <= ISCLOSE_ATOL:
        return FALL, math.nan
    if vx <= 0.0:
        return BACKWARD, math.nan
    potential = mass * gravity * y_apex
    return APEX, potential / (potential + mass / 2.0 * vx**2)


@parallel_kernel
def _apex_steps(
    states, actions, mass, stiffness, resting_length, gravity, energy, stance_step, max_time, reached, outcome
):
    for i in prange(states.shape[0]):
        outcome[i], reached[i, 0] = _apex_step(
            states[i, 0], actions[i, 0], mass, stiffness, resting_length, gravity, energy, stance_step, max_time
        )


def slip_outcomes(states: np.ndarray, actions: np.ndarray, hopper: SlipHopper = SlipHopper()):
    """One step from each row: ``(next_states (N, 1), outcomes (N,) int8)``, outcomes as
    :class:`SlipOutcome` values and the next state NaN where the step failed.

    Args:
        states: (N, 1) normalised apex heights ``s`` [-].
        actions: (N, 1) angles of attack [rad].
    """
    states = np.ascontiguousarray(states, dtype=np.float64)
    actions = np.ascontiguousarray(actions, dtype=np.float64)
    if states.ndim != 2 or states.shape[1] != 1 or actions.shape != states.shape:
        raise ValueError(f"states and actions must both be (N, 1), got {states.shape} and {actions.shape}")
    reached = np.empty_like(states)
    outcome = np.empty(states.shape[0], dtype=np.int8)
    _apex_steps(states, actions, *hopper.kernel_args(), reached, outcome)
    return reached, outcome


def slip_step(states: np.ndarray, actions: np.ndarray, hopper: SlipHopper = SlipHopper()):
    """vibly's SLIP step map for :func:`sim_core.viability.engine.compute_viability`: ``(next_states (N, 1),
    failed (N,) bool)`` from ``states`` (N, 1) normalised apex heights and ``actions`` (N, 1) angles
    of attack [rad]."""
    reached, outcome = slip_outcomes(states, actions, hopper)
    return reached, outcome != APEX


def slip_step_map(hopper: SlipHopper = SlipHopper()):
    """:func:`slip_step` for ``hopper``, as a ``step_map(states, actions)``."""

    def step(states: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return slip_step(states, actions, hopper)

    return step
