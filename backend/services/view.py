"""The 3D view as the service sees it: an interface the frontend implements.

The view (``frontend.viewer``) sits above the backend in the layers, so the service does not
import it: ``create_app`` takes a factory that builds one from a :class:`ViewContext`, and the
routes under ``/api/v1/view`` talk to whatever it built through :class:`SceneView`.
:class:`ViewStarter` builds it off the start-up path, so the API answers while viser and the
simulator load.

The view reads the store and the robot only through this module: :func:`stored_path` (a stored
run's path and its world, for replay and sharing), :func:`stored_path_key` (what a cached replay
was made of), :func:`stored_worlds` and :func:`stored_world` (the worlds simulate mode plans in
and a live run climbs), :func:`stored_plan_footholds` (the plan a live run follows) and
:func:`commanded` (a live run's command for a leg, named by its wall).
"""

from __future__ import annotations

import datetime
import logging
import threading
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from backend.errors import Conflict
from backend.repositories import jobs as job_rows
from backend.repositories import runs as run_rows
from backend.repositories import worlds as world_rows
from backend.robot.messages import Leg
from backend.services.robot import RobotService
from backend.services.worlds import world_in_l0
from backend.store.trajectory_blob import unpack_trajectory
from sim_core.model.controls import LegControl
from sim_core.model.walls import Wall
from sim_core.world.world import SIDES

if TYPE_CHECKING:
    from backend.robot.live_run import RunSnapshot


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
        """Replay a stored run in panel ``viewer``'s view only (NotFound / Conflict when it
        cannot be); returns info(viewer)."""
        ...

    def share_html(self, run_id: int, overlay_run_id: int | None = None) -> str:
        """A standalone HTML file that plays the stored run."""
        ...

    def close(self) -> None: ...


ViewFactory = Callable[[ViewContext], SceneView]


@dataclass(frozen=True)
class StoredPath:
    """A stored run as the 3D view replays it, read in one database session.

    Attributes:
        run_id, kind: which run, and its kind (``sim``, ``robot`` or ``replay``).
        model: its nondimensional model parameters as stored (``ModelParams``' fields and more).
        controls: ``[[psi0_deg, zeta0], ...]``, one pair per leg.
        start_state: the section state it started from (nondimensional).
        jumps: the jumps asked for.
        path: the stored path's columns: a sim run's sampled path (nondimensional), or the
            tracker frames (``time`` [s], ``x``, ``y`` [m]) of a robot run or of a replay run's
            source run; None when none was stored.
        touchdowns: the touchdowns found live (``time`` [s], ``wall``, ``foot_height`` [m]) of a
            robot or replay run; empty for a sim run.
        jumps_completed, climb: how far it went: jumps done, height gained [l0] (None: not read).
        created_at: when it was stored (UTC; None: not read).
        status, end_reason: how it ended (a robot run's reason, e.g. "e-stop"; None: not read).
        loop, controller, target: how it was driven ("open"/"closed", "pid", the height held [m]).
        world_id, world: the stored world it climbed and that world's §8 JSON in ``l0`` (None:
            parallel walls).
    """

    run_id: int
    kind: str
    model: dict
    controls: list
    start_state: list
    jumps: int
    path: dict[str, np.ndarray] | None
    touchdowns: list[dict]
    jumps_completed: int | None = None
    climb: float | None = None
    created_at: datetime.datetime | None = None
    status: str | None = None
    end_reason: str | None = None
    loop: str | None = None
    controller: str | None = None
    target: float | None = None
    world_id: int | None = None
    world: dict | None = None


VIEW_PRESET = "paper"  # a world stored in metres is read at this robot's leg length (the view's size)


def stored_path(sessions: Callable, run_id: int) -> StoredPath:
    """Stored run ``run_id`` as the view replays it, with the world it climbed (read in ``l0``).
    Raises NotFound when there is no such run, Conflict when a robot or replay run has no tracker
    frames."""
    with sessions() as session:
        run = run_rows.get_run(session, run_id)
        world = None if run.world_id is None else world_in_l0(session, run.world_id, VIEW_PRESET)
        source = run
        if run.kind == "replay":
            source = run_rows.get_run(session, int(run.results.get("source_run_id", 0)) or run_id)
        if run.kind != "sim" and source.trajectory is None:
            raise Conflict(f"run {run_id} has no tracker frames to replay")
        path = None if source.trajectory is None else unpack_trajectory(source.trajectory)
        touchdowns = [] if run.kind == "sim" else list(run.results.get("touchdowns", []))
        return StoredPath(
            run.id, run.kind, run.model, run.controls, run.start_state, run.jumps, path, touchdowns,
            jumps_completed=run.jumps_completed, climb=run.climb, created_at=run.created_at, status=run.status,
            end_reason=run.end_reason, loop=run.loop, controller=run.controller, target=run.target,
            world_id=run.world_id, world=world,
        )  # fmt: skip


def stored_worlds(sessions: Callable, limit: int = 100) -> list[tuple[int, str]]:
    """The stored worlds' ``(id, name)``, newest first (at most ``limit``)."""
    with sessions() as session:
        worlds, _next = world_rows.page(session, limit=limit, cursor=None)
        return [(world.id, world.name) for world in worlds]


def stored_world(sessions: Callable, world_id: int) -> dict:
    """Stored world ``world_id`` as the §8 JSON in ``l0`` (NotFound: none)."""
    with sessions() as session:
        return world_in_l0(session, world_id, VIEW_PRESET)


def stored_plan_footholds(sessions: Callable, job_id: int) -> list[tuple[int, int, float, float]]:
    """Plan job ``job_id``'s footholds, one per touchdown of its climb: side (0 left, 1 right),
    segment, and target ``x``, ``y`` [l0]; none when it holds no plan (NotFound: no such job)."""
    with sessions() as session:
        job = job_rows.get(session, job_id)
        steps = ((job.result or {}).get("plan") or []) if job.kind == "plan" else []
        return [(SIDES.index(step["side"]), int(step["segment"]), *map(float, step["target"])) for step in steps]


def stored_path_key(sessions: Callable, run_id: int) -> tuple:
    """A short stand-in for what :func:`stored_path` reads of run ``run_id``: equal keys, equal
    paths (for a cache). Runs change only in their tags and notes, which a path leaves out, but
    an id is taken again after a deletion (SQLite reuses the highest), and a robot run gets its
    frames when it ends: each run read is keyed by id, creation time, status and a checksum of
    its stored path. Raises NotFound as stored_path does."""
    with sessions() as session:
        run = run_rows.get_run(session, run_id)
        read = [run]
        if run.kind == "replay":
            read.append(run_rows.get_run(session, int(run.results.get("source_run_id", 0)) or run_id))
        return tuple(
            (r.id, r.created_at, r.status, None if r.trajectory is None else zlib.crc32(r.trajectory)) for r in read
        )


def commanded(run: RunSnapshot, wall: Wall) -> LegControl | None:
    """What live run ``run`` commands the leg that stands on ``wall`` to now (None: nothing yet)."""
    return run.command_for(Leg.of(wall))


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
