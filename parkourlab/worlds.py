"""Worlds through the client: store one (the §8 JSON, a named world, or random footholds from a
seed), list, read back as posted, rename, delete; and the jobs that work in worlds (a foothold
study, a plan, Mean Jumps To Failure in a world, the reach of a grid of schedules), followed as any
job (:mod:`parkourlab.jobs`). The part of :class:`parkourlab.Client` that deals with ``/api/v1/worlds`` (docs/worlds.md,
"Worlds in the service")."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from parkourlab.bodies import Leg, State, legs, mapping, present
from parkourlab.bodies import state as body_state
from parkourlab.types import Job, World

if TYPE_CHECKING:
    from parkourlab._http import Http

DEFAULT_PAGE_SIZE = 50


class WorldCalls:
    """World calls, mixed into :class:`parkourlab.Client` (which provides ``_http``)."""

    _http: Http

    def create_world(
        self,
        name: str,
        *,
        world: Mapping[str, Any] | None = None,
        named: str | None = None,
        random: Mapping[str, Any] | None = None,
        preset: str | None = None,
    ) -> World:
        """Store a world as ``name`` from exactly one of: ``world`` (a world file's JSON,
        docs/model.md §8 — e.g. ``json.load`` of one), ``named`` (``"staircase"``, ...) or ``random``
        (``{"seed": 7, "holds": 12, ...}``, ``parkour world random``'s options). ``preset``: the
        robot whose leg length converts a world in metres (default ``paper``). A malformed world
        raises :class:`~parkourlab.InvalidRequest` naming the side and point or segment."""
        body = {"name": name, "world": mapping(world), "named": named, "random": mapping(random), "preset": preset}
        return self._http.call("POST", "/api/v1/worlds", body=present(body))

    def worlds(self, *, page_size: int = DEFAULT_PAGE_SIZE) -> Iterator[World]:
        """Every stored world, newest first, page after page."""
        return self._http.pages("/api/v1/worlds", {}, page_size)

    def world(self, world_id: int) -> World:
        """A stored world; its ``world`` is the §8 JSON exactly as it was posted."""
        return self._http.call("GET", f"/api/v1/worlds/{world_id}")

    def rename_world(self, world_id: int, name: str) -> World:
        return self._http.call("PATCH", f"/api/v1/worlds/{world_id}", body={"name": name})

    def delete_world(self, world_id: int) -> None:
        """Delete a world; :class:`~parkourlab.Conflict` (naming one) while a run or job uses it."""
        self._http.call("DELETE", f"/api/v1/worlds/{world_id}")

    def submit_foothold_study(
        self,
        goal_height_m: float,
        *,
        world_id: int | None = None,
        random_worlds: Mapping[str, int] | None = None,
        trials: int | None = None,
        cap: int | None = None,
        seed: int | None = None,
        noise: Mapping[str, float] | None = None,
        state: State | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The foothold study (``parkour foothold-study``) on the stored world ``world_id`` or on
        ``random_worlds`` (``{"count", "seed0"}``): foot placement following a plan against the best
        fixed schedule, ``trials`` noisy climbs a world and method to a foot at ``goal_height_m``
        [m]. Its result is the command's ``--json``; each world is stored as it finishes (a
        restarted service goes on from there)."""
        spec = {"world_id": world_id, "random_worlds": mapping(random_worlds), "goal_height_m": goal_height_m}
        spec |= {"trials": trials, "cap": cap, "seed": seed, "noise": mapping(noise), "state": body_state(state)}
        return self._job("foothold-study", spec, model, experiment_id)

    def submit_plan(
        self,
        world_id: int,
        goal_height_m: float,
        *,
        launch_gait: bool | None = None,
        attempts: int | None = None,
        replans: int | None = None,
        cap: int | None = None,
        seed: int | None = None,
        noise: Mapping[str, float] | None = None,
        state: State | None = None,
        importance_sampling: Mapping[str, Any] | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The most robust plan up the stored world ``world_id`` to ``goal_height_m`` [m] (``parkour
        plan``); with ``attempts``, that many noisy climbs of it by the placement law, counted;
        with ``importance_sampling`` (``{"trials", "scale", "draws", "first_leg"}``), importance-
        sampled climbs for a failure chance too rare for plain attempts (docs/worlds.md).
        ``launch_gait``: from the velocity a robot launched on the plan's first leg has (for a live
        run that follows it, ``RobotRunCreate.plan_job_id``)."""
        spec = {
            "world_id": world_id,
            "goal_height_m": goal_height_m,
            "attempts": attempts,
            "replans": replans,
            "launch_gait": launch_gait,
            "importance_sampling": None if importance_sampling is None else dict(importance_sampling),
        }
        spec |= {"cap": cap, "seed": seed, "noise": mapping(noise), "state": body_state(state)}
        return self._job("plan", spec, model, experiment_id)

    def submit_world_mjtf(
        self,
        world_id: int,
        controls: Sequence[Leg],
        *,
        goal_height_m: float | None = None,
        trials: int | None = None,
        cap: int | None = None,
        seed: int | None = None,
        noise: Mapping[str, float] | None = None,
        state: State | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """Mean Jumps To Failure in the stored world ``world_id``: ``trials`` noisy climbs of
        ``controls`` (legs ``(psi0_deg, zeta0)`` in turn), each to a failure, ``cap`` jumps or a
        foot at ``goal_height_m`` [m]."""
        spec = {"world_id": world_id, "controls": legs(controls), "goal_height_m": goal_height_m, "trials": trials}
        spec |= {"cap": cap, "seed": seed, "noise": mapping(noise), "state": body_state(state)}
        return self._job("world-mjtf", spec, model, experiment_id)

    def submit_reach(
        self,
        world_id: int,
        *,
        psi0_range: Sequence[float] | None = None,
        psi0_steps: int | None = None,
        zeta0_range: Sequence[float] | None = None,
        zeta0_steps: int | None = None,
        jumps: int | None = None,
        foot_y: float | None = None,
        state: State | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The reach of a grid of symmetric schedules in the stored world ``world_id`` (``parkour
        reach``): ``psi0_steps`` leg angles over ``psi0_range`` ``(low, high)`` [deg] by
        ``zeta0_steps`` leg lengths over ``zeta0_range`` [l0], each climbing up to ``jumps`` jumps
        from touchdown 0 (the foot on the left side at ``foot_y`` [l0]). Its result is the
        command's ``--json``: each cell's highest foot [l0] and how it ended."""
        spec = {"world_id": world_id, "psi0_range": _pair(psi0_range), "psi0_steps": psi0_steps}
        spec |= {"zeta0_range": _pair(zeta0_range), "zeta0_steps": zeta0_steps, "jumps": jumps, "foot_y": foot_y}
        return self._job("reach", spec | {"state": body_state(state)}, model, experiment_id)

    def _job(self, kind: str, spec: dict, model: Mapping[str, Any] | None, experiment_id: int | None) -> Job:
        body = {"kind": kind} | present(spec | {"model": mapping(model), "experiment_id": experiment_id})
        return self._http.call("POST", "/api/v1/jobs", body=body)


def _pair(values: Sequence[float] | None) -> list[float] | None:
    """A ``(low, high)`` range as the API takes it: a list (None stays None)."""
    return None if values is None else list(values)
