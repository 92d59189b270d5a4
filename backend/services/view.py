"""The 3D view as the service sees it: an interface the frontend implements.

The view (``frontend.viewer``) sits above the backend in the layers, so the service does not
import it: ``create_app`` takes a factory that builds one from a :class:`ViewContext`, and the
routes under ``/api/v1/view`` talk to whatever it built through :class:`SceneView`.
:class:`ViewStarter` builds it off the start-up path, so the API answers while viser and the
simulator load.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from backend.services.robot import RobotService


@dataclass(frozen=True)
class ViewContext:
    """What the service lends its view: database sessions and the robot link."""

    sessions: Callable
    robot_service: RobotService | None


class SceneView(Protocol):
    """A view per browser; a control panel names the one it embeds by a viewer id."""

    def info(self, viewer: str | None = None) -> dict:
        """``available``, ``port``, ``updates_per_s``, ``clients``; ``mode`` and ``run_id`` of the
        view of panel ``viewer``."""
        ...

    def open_run(self, viewer: str, run_id: int, overlay_run_id: int | None = None) -> dict:
        """Replay a stored run in panel ``viewer``'s view only (records.NotFound /
        records.Conflict when it cannot be); returns info(viewer)."""
        ...

    def share_html(self, run_id: int, overlay_run_id: int | None = None) -> str:
        """A standalone HTML file that plays the stored run."""
        ...

    def close(self) -> None: ...


ViewFactory = Callable[[ViewContext], SceneView]

log = logging.getLogger("parkourlab.view")
CLOSE_WAIT_S = 30.0  # a view still starting at shutdown is waited for, then closed


class ViewStarter:
    """Builds the 3D view in a thread of its own and owns it from then on.

    The view is written once, by the starting thread; readers get it (or None) through
    :attr:`view` and, while there is none, the reason through :attr:`unavailable_reason`.
    """

    def __init__(self, factory: ViewFactory, context: ViewContext):
        self._factory, self._context = factory, context
        self._view: SceneView | None = None
        self._error: str | None = None
        self._done = threading.Event()
        self._lock = threading.Lock()  # orders "built" against "closed": a view built after close() is closed
        self._closed = False
        self._thread = threading.Thread(target=self._start, name="view-start", daemon=True)

    def start(self) -> ViewStarter:
        self._thread.start()
        return self

    def _start(self) -> None:
        try:
            view = self._factory(self._context)
        except Exception as error:  # the API keeps running without a view, and says why
            log.exception("the 3D view did not start")
            self._error = f"the 3D view did not start: {error}"
            self._done.set()
            return
        with self._lock:
            closed = self._closed
            if not closed:
                self._view = view
        if closed:  # the service shut down while the view was being built
            view.close()
        self._done.set()

    @property
    def view(self) -> SceneView | None:
        return self._view

    @property
    def starting(self) -> bool:
        return not self._done.is_set()

    @property
    def unavailable_reason(self) -> str:
        if self._error is not None:
            return self._error
        return "the 3D view is starting; try again in a moment" if not self._done.is_set() else "no 3D view"

    def wait(self, timeout: float | None = None) -> SceneView | None:
        """The view once its start has ended (None if it failed or ``timeout`` [s] passed)."""
        self._done.wait(timeout)
        return self._view

    def close(self) -> None:
        """Close the view; one still being built is closed once built (waited for up to
        :data:`CLOSE_WAIT_S`, then left to close itself)."""
        self._done.wait(CLOSE_WAIT_S)
        with self._lock:
            self._closed = True
            view, self._view = self._view, None
        if view is not None:
            view.close()
