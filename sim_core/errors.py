"""The errors a user can fix, in one light module (no numba, no scipy).

Callers that only need to recognise these errors — the ``parkour`` command's error handler, the
API's error mapping — import them from here without loading the kernels.
"""

from __future__ import annotations


class ParameterError(ValueError):
    """A parameter, control or state is outside its allowed range.

    ``field`` is the name the user knows (``"zeta0"``, ``"alpha"``); the message says the
    allowed range and the value received.
    """

    def __init__(self, field: str, message: str):
        super().__init__(f"{field}: {message}")
        self.field = field


class FixedPointNotFound(RuntimeError):
    """Levenberg–Marquardt did not converge to a fixed point from the given guess."""
