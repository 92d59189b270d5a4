"""A new run, as produced and before it is stored: a plain frozen dataclass with no database
imports, so the compute workers that produce runs never load SQLAlchemy
(:func:`backend.repositories.runs.add_run` turns one into the row)."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class RunRecord:
    """A run as produced, before it is stored. ``model`` is the nondimensional parameters (a
    ``ModelParams`` as a JSON dict), ``controls`` ``[[psi0_deg, zeta0], …]`` per leg, ``start_state``
    the first section state ``[xdot, ydot]``, ``climb`` the total height gain [l0]."""

    kind: str
    status: str
    model: dict
    controls: list
    start_state: list
    jumps: int
    jumps_completed: int
    climb: float
    results: dict
    code_version: str
    failure_code: str | None = None
    duration_s: float = 0.0  # [s] wall-clock time it took
    trajectory: bytes | None = None  # the sampled path (backend.store.trajectory_blob.pack_trajectory)
    world_id: int | None = None  # the stored world it ran in (None: parallel walls)
    tags: tuple[str, ...] = field(default=())
