"""The 3D view's three modes, each a GUI folder plus a ``frame(dt)`` the view's loop calls.

Every browser has its own three (:mod:`frontend.viewer.session`): the GUI and scene they draw
are that browser's (``client.gui``, ``client.scene``), so one person's sliders, play state and
replay are theirs alone.

- :class:`~frontend.viewer.modes.simulate.SimulateMode` — the model climbs in real time; sliders
  act from the next touchdown (its gait readout: :mod:`frontend.viewer.modes.gait_search`);
- :class:`~frontend.viewer.modes.live.LiveMode` — the body follows the robot's tracker stream,
  the model's prediction of the jump under way beside it as a ghost;
- :class:`~frontend.viewer.modes.replay.ReplayMode` — a stored run on a timeline, optionally with
  a second run as a ghost, drawn by :func:`frontend.viewer.modes.painter.show_frame`.

GUI handles are named ``gui_*``. Setting a handle's value from Python runs its callbacks
(viser calls them synchronously), so code that sets values does it inside ``self._quietly()``
and the callbacks ignore what happens there: no feedback loops.
"""

from __future__ import annotations

import contextlib
import math
from abc import ABC, abstractmethod

import viser

from frontend.viewer.scene import ChuteScene


def _range_words(low, high) -> str:
    if low is not None and high is not None:
        return f"{low:g} to {high:g}"
    return f"at least {low:g}" if low is not None else f"at most {high:g}"


class Mode(ABC):
    """What the session needs of a mode: ``name``, ``folder`` (its GUI), ``gui_readout``,
    :meth:`activate` / :meth:`deactivate`, ``frame(dt)`` and ``readout(updates_per_s)``.

    ``lock`` is the browser's session's: the loop holds it for each frame, callbacks for each change.
    """

    name: str
    folder: viser.GuiFolderHandle
    gui_readout: viser.GuiMarkdownHandle

    def __init__(self, client: viser.ClientHandle, scene: ChuteScene, lock):
        self.client, self.scene, self.lock = client, scene, lock
        self._quiet = False

    @contextlib.contextmanager
    def _quietly(self):
        self._quiet, before = True, self._quiet
        try:
            yield
        finally:
            self._quiet = before

    def activate(self) -> None:
        self.folder.visible = True

    def deactivate(self) -> None:
        self.folder.visible = False

    @abstractmethod
    def frame(self, dt: float) -> None:
        """Draw the mode ``dt`` [s] after its last frame."""

    @abstractmethod
    def readout(self, updates_per_s: float) -> str:
        """The markdown under the mode's GUI; ``updates_per_s``: the view's frame rate [1/s]."""

    @staticmethod
    def _out_of_range(handles) -> str | None:
        """Why the values in ``handles`` (sliders, number boxes) cannot be used yet, or None. A
        number box sends what is typed as it is typed: "0" on the way to "0.9", or nothing."""
        problems = []
        for handle in handles:
            value, low, high = handle.value, handle.min, handle.max
            usable = isinstance(value, int | float) and math.isfinite(value)
            if not usable or (low is not None and value < low) or (high is not None and value > high):
                problems.append(f"{handle.label} must be {_range_words(low, high)}")
        return "; ".join(problems) or None

    @staticmethod
    def _clamped(handle, default: float) -> float:
        """A slider's value held to its range (``default`` where it holds no number)."""
        value = handle.value
        if not isinstance(value, int | float) or not math.isfinite(value):
            return default
        return float(min(max(value, handle.min), handle.max))
