"""A controller closed on the robot: the compiled law of :mod:`sim_core.control.controllers`, stepped once
per detected touchdown by a live run's loop (its one owner, the loop's thread).

At detected touchdown ``i`` (the climb's touchdown ``i + 1``) the law sees what the robot
observes there — the body's height, the pitch the tracker gave for that stance (NaN when the
markers gave none) and the section state fitted from the flight before it — and returns the
controls of the climb's next touchdown, ``i + 2``: the leg the robot positions during the coming
stance. Heights are the tracker's [m] over the leg length, the frame ``target_m`` is given in,
so the law's target and heights share an origin. The ``pid`` law is today's loop
(:func:`sim_core.control.closed_loop.pid_step`, each leg keeping its own angle; the error now taken as
``target / l0 - height / l0``, the same to rounding); the others command the angle too. Every
command says which law, whether it was clipped to the leg's range, and the law's state after it
(the PID's integral and last error; the LQR's and deadbeat's last command).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from backend.robot.limits import ServoLimits
from backend.robot.touchdown import Touchdown, pitch_before
from sim_core.control.design import SteppedLaw, law_holding
from sim_core.control.laws import Controller
from sim_core.control.registry import LAWS
from sim_core.model.controls import NO_OFFSETS, LegControl, LegOffsets
from sim_core.model.params import PhysicalParams
from sim_core.model.validation import check_range
from sim_core.model.walls import Wall, wall_of


@dataclass
class LiveLaw:
    """``law`` holding ``target_m`` [m] on a robot of ``leg_length`` [m], whose first detected
    touchdown is made with ``first`` (the right leg's start controls: the climb's touchdown 1).
    ``offsets``: the legs' servo offsets a calibration found (:class:`sim_core.model.controls.LegOffsets`);
    each command is the law's less its leg's offset, so the leg realises what the law chose, held
    to the servos' ``limits`` (clipped, and said so, where the offset would take it past them)."""

    target_m: float
    law: Controller
    leg_length: float  # [m]
    first: LegControl
    offsets: LegOffsets = NO_OFFSETS
    limits: ServoLimits = field(default_factory=ServoLimits)

    def __post_init__(self) -> None:
        self.stepped = SteppedLaw(self.law, self.first)  # compiled before the run starts
        self._psi0_offset = tuple(math.radians(offset) for offset in self.offsets.psi0_offset_deg)

    @property
    def name(self) -> str:
        return self.law.name

    @property
    def memory(self) -> np.ndarray:
        return self.stepped.memory

    def command(self, touchdown: Touchdown, pitch: float, leg_psi0: float) -> tuple[LegControl, dict]:
        """The next touchdown's controls after detected ``touchdown`` (``pitch`` [rad] tracked in
        its stance; ``leg_psi0`` [rad] the angle that leg holds now, which ``pid`` keeps), and
        what the journal keeps of it: the law, clipping and its state after the step."""
        wall = wall_of(touchdown.index + 2)  # the next touchdown's
        height = touchdown.body_height / self.leg_length
        psi0, zeta0, clipped = self.stepped.step(height, pitch, *touchdown.state, wall == Wall.LEFT)
        side = 1 if wall == Wall.RIGHT else 0
        angle = psi0 - self._psi0_offset[side] if LAWS[self.name].sets_leg_angle else leg_psi0
        held, clipped_here = self.limits.held(angle, zeta0 - self.offsets.zeta0_offset[side])
        clipped = clipped or clipped_here
        journal = {"controller": self.name, "clipped": clipped, "state": self.stepped.state}
        return LegControl(*held), journal


def pitch_at(time: np.ndarray, pitch: np.ndarray, at: float) -> float:
    """The pitch [rad] the tracker gave at time ``at`` [s]: of the last pose at or before it, else
    the newest one looked back to (:func:`backend.robot.touchdown.pitch_before`); NaN when none has."""
    return pitch_before(pitch, int(np.searchsorted(time, at, side="right")) - 1, math.nan)


def live_law_for(
    loop, robot: PhysicalParams, legs: list[LegControl], limits: ServoLimits, *, offsets: LegOffsets = NO_OFFSETS
) -> LiveLaw:
    """The closed loop ``loop`` (a :class:`backend.schemas.ClosedLoopIn`) as the run's law: about
    the in-place zeta0 at the left leg's angle, designed on ``robot``'s model (the LQR's gains and
    the deadbeat's predictions from it: a calibrated preset gives its own, and its leg
    ``offsets`` come off each command), its commands within the servos' ``limits``, compiled
    before anything moves. A law that cannot be built, or a
    zeta0 range the servos cannot reach, is a ParameterError naming the field (a 422)."""
    for name in ("zeta0_min", "zeta0_max"):
        check_range(f"closed_loop.{name}", getattr(loop, name), *limits.zeta0, low_open=False, high_open=False)
    law = law_holding(loop.controller, robot.to_model(), loop.target_m / robot.leg_length, legs[0].psi0_deg,
                      gains=(loop.kp, loop.ki, loop.kd), zeta0_range=(loop.zeta0_min, loop.zeta0_max),
                      psi0_range_deg=limits.psi0_deg, climb_per_jump=loop.climb_per_jump)  # fmt: skip
    return LiveLaw(loop.target_m, law, robot.leg_length, legs[1], offsets, limits)
