"""The controllers closed once per jump, as data: a module per law, its parameters as a frozen
dataclass (checked, naming the field) that gives the compiled loop its branch (``NUMBER``) and a
flat parameter array. NumPy only. Which laws exist, by name, and how each is designed is the
registry's (:mod:`sim_core.control.registry`); a law's compiled step is a branch of
:func:`sim_core.control.controllers.control_step`.
"""

from __future__ import annotations

from sim_core.control.laws import deadbeat, lqr, pid
from sim_core.control.laws.common import DEADBEAT_CLIMB_PER_JUMP, MEMORY_SIZE, PSI0_RANGE_DEG, DesignRequest
from sim_core.control.laws.deadbeat import Deadbeat, Placement
from sim_core.control.laws.lqr import Lqr
from sim_core.control.laws.pid import Pid

Controller = Pid | Lqr | Deadbeat | Placement  # what every front end hands the compiled loop
PID, PID_PITCH, LQR, DEADBEAT = pid.NUMBER, pid.PITCH_NUMBER, lqr.NUMBER, deadbeat.NUMBER  # the compiled branches
PLACEMENT = deadbeat.PLACEMENT_NUMBER

__all__ = [
    "DEADBEAT",
    "DEADBEAT_CLIMB_PER_JUMP",
    "LQR",
    "MEMORY_SIZE",
    "PID",
    "PID_PITCH",
    "PLACEMENT",
    "PSI0_RANGE_DEG",
    "Controller",
    "Deadbeat",
    "DesignRequest",
    "Lqr",
    "Pid",
    "Placement",
]
