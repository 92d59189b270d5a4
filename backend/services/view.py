"""The 3D view as the service sees it: an interface the frontend implements.

The view (``frontend.viewer``) sits above the backend in the layers, so the service does not
import it: ``create_app`` takes a factory that builds one from a :class:`ViewContext`, and the
routes under ``/api/v1/view`` talk to whatever it built through :class:`SceneView`.
"""

from __future__ import annotations

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
    def info(self) -> dict:
        """``available``, ``port``, ``mode``, ``run_id``, ``updates_per_s``, ``clients``."""
        ...

    def open_run(self, run_id: int, overlay_run_id: int | None = None) -> dict:
        """Replay a stored run (records.NotFound / records.Conflict when it cannot be); returns info()."""
        ...

    def share_html(self, run_id: int, overlay_run_id: int | None = None) -> str:
        """A standalone HTML file that plays the stored run."""
        ...

    def close(self) -> None: ...


ViewFactory = Callable[[ViewContext], SceneView]
