"""Failure modes of a jump (docs/model.md §3), and the end of a closed loop's run on the floor.

The compiled kernels return small integers (they cannot raise); everything outside the
kernels speaks :class:`Failure`, whose ``code`` strings are the stable names used in JSON
output, the database and the UI. Never renumber: stored results refer to these codes.
"""

from __future__ import annotations

from enum import IntEnum

# Kernel status values. Module constants so numba can inline them.
OK = 0
SLIP = 1
COLLAPSE = 2
NO_LIFTOFF = 3
NO_FLIGHT = 4
INVALID_STATE = 5
FLOOR = 6  # a closed loop's run only: the body came down to the chute's floor
NO_TOUCHDOWN = 7  # a world's flight (docs/model.md §8): the foot met no side within the flight's cap
FLOOR_HEIGHT = 0.0  # [l0] that floor (sim_core.climb.records.FLOOR): where the climb's first foot touched


class Failure(IntEnum):
    """Why a jump ended the run. ``Failure(status)`` converts a kernel status."""

    SLIP = SLIP
    COLLAPSE = COLLAPSE
    NO_LIFTOFF = NO_LIFTOFF
    NO_FLIGHT = NO_FLIGHT
    INVALID_STATE = INVALID_STATE
    FLOOR = FLOOR
    NO_TOUCHDOWN = NO_TOUCHDOWN

    @property
    def code(self) -> str:
        """Stable lower-case name, e.g. ``"slip"``."""
        return self.name.lower()

    @property
    def message(self) -> str:
        """One sentence a person can act on."""
        return _MESSAGES[self]

    @classmethod
    def from_code(cls, code: str) -> Failure:
        try:
            return cls[code.upper()]
        except KeyError:
            allowed = ", ".join(f.code for f in cls)
            raise ValueError(f"unknown failure code {code!r}; allowed: {allowed}") from None


_MESSAGES = {
    Failure.SLIP: "the leg left the friction cone (|tan psi| > mu) during stance",
    Failure.COLLAPSE: "the leg collapsed: the body reached the foot during stance",
    Failure.NO_LIFTOFF: "the spring never re-extended: stance exceeded its time cap",
    Failure.NO_FLIGHT: "no flight phase: at lift-off the body does not head for the other wall",
    Failure.INVALID_STATE: "non-finite numbers or a state outside the model's domain",
    Failure.FLOOR: "the body reached the chute's floor",  # as the climb's end (sim_core.climb.records.ClimbEnd)
    Failure.NO_TOUCHDOWN: "the foot reached no wall: the flight passed its time cap",
}
