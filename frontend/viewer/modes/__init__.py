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

Typed values are refused, never clamped. A number box sends what is typed as it is typed ("0"
on the way to "0.9"), and when it loses focus the browser holds its value to the box's ends: a
slider's box to the slider's ends, so psi0 80 became 60 and was used. So each ranged control
(:meth:`Mode._ranged_slider`, :meth:`Mode._ranged_number`) keeps its valid range here: a
slider's track and box reach one step past each end (its marks show the valid ends), so what the
browser holds a typed 80 to is 60.5, refused like 80; a number box has no ends in the browser at
all. A value outside its range is not used (:meth:`Mode._out_of_range` says why, naming the
control and its range; :meth:`Mode._usable` gives the value in use instead).
"""

from __future__ import annotations

import contextlib
import math
from abc import ABC, abstractmethod

import viser

from frontend.viewer.scene import ChuteScene
from frontend.viewer.viser_adapter import set_slider_marks


def _range_words(low, high, whole: bool = False) -> str:
    number = (lambda v: str(int(v))) if whole else (lambda v: f"{v:g}")
    if low is not None and high is not None:
        return f"{'a whole number from ' if whole else ''}{number(low)} to {number(high)}"
    kind = "a whole number, " if whole else ""
    return f"{kind}at least {number(low)}" if low is not None else f"{kind}at most {number(high)}"


def _shown(value) -> str:
    return f"{value:g}" if isinstance(value, int | float) and not isinstance(value, bool) else "nothing usable"


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
        self._ranges: dict[int, tuple[float, float, bool]] = {}  # id(handle) -> its valid low, high, whole
        self._typed: dict[int, float] = {}  # id(handle) -> the last value typed past its box's ends

    # Ranged controls ----------------------------------------------------------------------------
    def _ranged_slider(self, label: str, low: float, high: float, step: float, initial: float, **options):
        """A slider for values in [``low``, ``high``]: its track and box one ``step`` wider on each
        side (the browser holds a typed value to those ends, refused too), its marks at the ends."""
        below, above = round(low - step, 12), round(high + step, 12)
        handle = self.client.gui.add_slider(
            label, below, above, step, initial, marks=((low, f"{low:g}"), (high, f"{high:g}")), **options
        )
        self._ranges[id(handle)] = (low, high, False)
        return handle

    def _set_range(self, handle, low: float, high: float, step: float) -> None:
        """A ranged slider's valid range moved (the replay's timeline: the run's length)."""
        handle.min, handle.max = round(low - step, 12), round(high + step, 12)
        set_slider_marks(handle, ((low, f"{low:g}"), (high, f"{high:g}")))
        self._ranges[id(handle)] = (low, high, False)

    def _ranged_number(self, label: str, initial: int, low: int, high: int | None = None, **options):
        """A number box for whole numbers from ``low`` (to ``high``): no ends in the browser, so
        nothing typed is changed there."""
        handle = self.client.gui.add_number(label, initial, step=1, **options)
        self._ranges[id(handle)] = (low, high, True)
        return handle

    def _problem(self, handle) -> str | None:
        """Why ``handle``'s value cannot be used, naming the control and its range, or None."""
        value = handle.value
        low, high, whole = self._ranges.get(id(handle), (handle.min, handle.max, False))
        usable = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
        inside = usable and (low is None or value >= low) and (high is None or value <= high)
        if inside and (not whole or float(value).is_integer()):
            self._typed.pop(id(handle), None)
            return None
        # At a slider box's end (one step past the range) after a value typed past that end: the
        # browser held it there, so say what was typed.
        typed, got = self._typed.get(id(handle)), value
        held = (
            usable
            and typed is not None
            and ((value == handle.max and typed > value) or (value == handle.min and typed < value))
        )
        if held:
            got = typed
        elif usable:
            self._typed[id(handle)] = value
        return f"{handle.label} must be {_range_words(low, high, whole)}, got {_shown(got)}"

    def _out_of_range(self, handles) -> str | None:
        """Why the values in ``handles`` (sliders, number boxes) cannot be used, or None: each
        control named with its range and what it got. A number box sends what is typed as it is
        typed ("0" on the way to "0.9"), and typed values are never clamped (above)."""
        problems = [problem for handle in handles if (problem := self._problem(handle)) is not None]
        return "; ".join(problems) or None

    def _usable(self, handle, in_use: float) -> float:
        """``handle``'s value if it is in its range, else ``in_use`` (the value in use until then)."""
        return in_use if self._problem(handle) is not None else float(handle.value)

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
