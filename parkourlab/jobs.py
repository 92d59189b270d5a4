"""Batch jobs through the client: submit (MJTF, sweep, basin, gait search, control study, MFPT of a
gait or a controller, viability), follow, wait, read results, cancel. The part of
:class:`parkourlab.Client` that deals with ``/api/v1/jobs``."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from parkourlab import frames
from parkourlab.bodies import Leg, State, legs, mapping, present, state
from parkourlab.types import Job, JobResults, JobState
from parkourlab.waiting import POLL_TIMEOUT, wait_for

if TYPE_CHECKING:
    from parkourlab._http import Http

JobRef = int | Mapping[str, Any]  # a job's id, or the job as the API gave it
DEFAULT_POLL_INTERVAL = 0.5  # [s] between two looks at a job's state while waiting


class JobCalls:
    """Job calls, mixed into :class:`parkourlab.Client` (which provides ``_http``)."""

    _http: Http

    def job_kinds(self) -> list[dict[str, Any]]:
        """The job kinds this service takes, in order: ``{"name", "title", "request"}`` each
        (``request``: its body's schema in the service's OpenAPI document), from its catalog."""
        return self._http.call("GET", "/api/v1/catalog")["job_kinds"]

    def submit_job(self, kind: str, **spec: Any) -> Job:
        """Queue a job of ``kind`` (one of :meth:`job_kinds`: ``mjtf``, ``sweep``, ``basin``,
        ``gaits``, ``control-study``, ``mfpt``, ``loop-mfpt``, ``viability`` today) with ``spec`` as
        its body (the API's field names; docs/service.md). Returns it queued (202). The typed
        ``submit_*`` methods below are the same with each field named."""
        body = {"kind": kind} | present(spec)
        return self._http.call("POST", "/api/v1/jobs", body=body)

    def submit_mjtf(
        self,
        zeta0s: Sequence[float],
        *,
        psi0_deg: float | None = None,
        trials: int | None = None,
        cap: int | None = None,
        seed: int | None = None,
        noise: Mapping[str, float] | None = None,
        guess: State | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """Mean Jumps To Failure: ``trials`` noisy climbs at each of the ``zeta0s`` [l0] (energy
        levels, each in (0, 1)) with leg angle ``psi0_deg`` [deg], each ended at failure or after
        ``cap`` jumps; ``seed`` fixes the noise draws; ``noise`` (``psi0_deg`` [deg], ``zeta0``
        [l0], ``velocity`` [sqrt(g l0)], ``pitch_drift_deg`` [deg] …, docs/model.md §5.1). None:
        the service's default. Its ``total`` is levels × trials."""
        spec = {"zeta0s": list(zeta0s), "psi0_deg": psi0_deg, "trials": trials, "cap": cap, "seed": seed}
        spec |= {"noise": mapping(noise), "guess": state(guess)}
        return self.submit_job("mjtf", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_sweep(
        self,
        *,
        zeta0_low: float | None = None,
        zeta0_high: float | None = None,
        steps: int | None = None,
        psi0_deg: float | None = None,
        basin_grid: int | None = None,
        basin_jumps: int | None = None,
        basin_jump_limit: int | None = None,
        guess: State | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """An energy sweep: the symmetric gait at ``psi0_deg`` [deg] followed over ``steps`` zeta0
        values [l0] from ``zeta0_low`` to ``zeta0_high``, each with its climb, max |λ| and (with
        ``basin_grid`` > 0) basin area over ``basin_grid``² states, ``basin_jumps`` jumps each (those
        still undecided continued up to ``basin_jump_limit`` jumps, if given). None: the service's default."""
        spec = {"zeta0_low": zeta0_low, "zeta0_high": zeta0_high, "steps": steps, "psi0_deg": psi0_deg}
        spec |= {"basin_grid": basin_grid, "basin_jumps": basin_jumps, "basin_jump_limit": basin_jump_limit}
        spec |= {"guess": state(guess)}
        return self.submit_job("sweep", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_basin(
        self,
        controls: Sequence[Leg],
        *,
        period: int | None = None,
        guess: State | None = None,
        grid: int | None = None,
        jumps: int | None = None,
        jump_limit: int | None = None,
        tolerance: float | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The basin of attraction of the gait of ``controls`` (``(psi0 [deg], zeta0 [l0])`` per
        leg) near ``guess`` ``(xdot, ydot)`` [sqrt(g l0)]: a ``grid`` × ``grid`` of section states,
        each followed ``jumps`` jumps (those still undecided continued, the cap doubled, up to
        ``jump_limit``, if given) and counted in when within ``tolerance`` of the gait."""
        spec = {"controls": legs(controls), "period": period, "guess": state(guess)}
        spec |= {"grid": grid, "jumps": jumps, "jump_limit": jump_limit, "tolerance": tolerance}
        return self.submit_job("basin", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_gaits(
        self,
        controls: Sequence[Leg],
        *,
        period: int | None = None,
        grid: int | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The distinct gaits of ``controls`` (``(psi0 [deg], zeta0 [l0])`` per leg), found from a
        ``grid`` × ``grid`` of guesses."""
        spec = {"controls": legs(controls), "period": period, "grid": grid}
        return self.submit_job("gaits", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_control_study(
        self,
        controllers: Sequence[str],
        *,
        target_m: float | None = None,
        seeds: int | None = None,
        seed0: int | None = None,
        jumps: int | None = None,
        psi0_deg: float | None = None,
        start_zeta0: float | None = None,
        noise: Mapping[str, float] | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The closed-loop benchmark (``parkour control-study``): each of ``controllers`` (``pid``,
        ``pid-pitch``, ``lqr`` …) climbing to ``target_m`` [m] from the climbing gait at
        ``psi0_deg`` [deg] and ``start_zeta0`` [l0], ``seeds`` trials of ``jumps`` jumps (seeds
        ``seed0``, ``seed0 + 1`` …), every controller on the same ``noise`` draws. Its result: per
        controller failures, height RMS and median error [m], jumps to rise, clipped commands
        (``results_frame`` gives a row each), and the panel's plots."""
        spec = {"controllers": list(controllers), "target_m": target_m, "seeds": seeds, "seed0": seed0}
        spec |= {"jumps": jumps, "psi0_deg": psi0_deg, "start_zeta0": start_zeta0, "noise": mapping(noise)}
        return self.submit_job("control-study", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_mfpt(
        self,
        *,
        psi0_deg: float | None = None,
        zeta0: float | None = None,
        start: State | None = None,
        guess: State | None = None,
        noise: Mapping[str, float] | None = None,
        grid: int | None = None,
        pitch_spacing: float | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """Mean first-passage time (``parkour mfpt``): the expected jumps to failure of symmetric
        controls ``psi0_deg`` [deg], ``zeta0`` [l0] under ``noise``, from ``start`` (a touchdown
        state; default the gait's fixed point, found from ``guess``), by a Markov chain on a grid of
        ``grid`` velocity nodes and ``pitch_spacing`` [pitch-step sigmas]. Its result: ``mfpt_jumps``,
        ``lambda2``, ``discretisation_error``, ``cells``, ``seconds`` and each grid's numbers."""
        spec = {"psi0_deg": psi0_deg, "zeta0": zeta0, "start": state(start), "guess": state(guess)}
        spec |= {"noise": mapping(noise), "grid": grid, "pitch_spacing": pitch_spacing}
        return self.submit_job("mfpt", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_loop_mfpt(
        self,
        controller: str,
        *,
        target_m: float | None = None,
        psi0_deg: float | None = None,
        start_zeta0: float | None = None,
        noise: Mapping[str, float] | None = None,
        replicas: int | None = None,
        runs: int | None = None,
        seed: int | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """A controller's mean first-passage time (``parkour mfpt --controller``): ``controller``
        (one of :meth:`controllers`: ``pid``, ``pid-pitch``, ``lqr``, ``deadbeat`` today) holding
        ``target_m`` [m] after the control study's climb from ``psi0_deg`` [deg], ``start_zeta0``
        [l0], under ``noise`` without pitch drift, by ``runs`` splitting runs of ``replicas`` each
        (replicas × runs bounded), every draw
        from ``seed``. Its result: ``mfpt_jumps``, ``ci95``, ``lambda2``, ``relative_error`` and the
        ``splitting``'s numbers (``probabilities``: each run's). None: the service's default."""
        spec = {"controller": controller, "target_m": target_m, "psi0_deg": psi0_deg, "start_zeta0": start_zeta0}
        spec |= {"noise": mapping(noise), "replicas": replicas, "runs": runs, "seed": seed}
        return self.submit_job("loop-mfpt", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_viability(
        self,
        *,
        states: int | None = None,
        actions: int | None = None,
        psi0_low_deg: float | None = None,
        psi0_high_deg: float | None = None,
        zeta0_low: float | None = None,
        zeta0_high: float | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The viability kernel (``parkour viability``): the mid-chute velocities from which some
        leg command keeps the robot jumping forever, on ``states`` nodes per velocity axis and
        ``actions`` per control axis over psi0 ``psi0_low_deg``-``psi0_high_deg`` [deg] and zeta0
        ``zeta0_low``-``zeta0_high`` [l0]. Its result: ``kernel_fraction``, ``kernel`` and
        ``measure`` over the states, the axes, and ``viable_pairs`` (base64 bits, see
        :mod:`backend.jobs.viability`)."""
        spec = {"states": states, "actions": actions, "psi0_low_deg": psi0_low_deg, "psi0_high_deg": psi0_high_deg}
        spec |= {"zeta0_low": zeta0_low, "zeta0_high": zeta0_high}
        return self.submit_job("viability", **spec, model=mapping(model), experiment_id=experiment_id)

    def submit_atlas(
        self,
        *,
        psi0_low_deg: float | None = None,
        psi0_high_deg: float | None = None,
        zeta0_low: float | None = None,
        zeta0_high: float | None = None,
        rows: int | None = None,
        columns: int | None = None,
        transient: int | None = None,
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
    ) -> Job:
        """The gait atlas (``parkour atlas``, symmetric): where stable gaits live over ``rows`` leg
        angles from ``psi0_low_deg`` to ``psi0_high_deg`` [deg] x ``columns`` leg lengths from
        ``zeta0_low`` to ``zeta0_high`` [l0], each orbit let settle ``transient`` jumps. Its result
        is ``parkour atlas --json``: per cell the most stable gait's period, climb per jump and max |λ|."""
        spec = {"psi0_low_deg": psi0_low_deg, "psi0_high_deg": psi0_high_deg, "zeta0_low": zeta0_low}
        spec |= {"zeta0_high": zeta0_high, "rows": rows, "columns": columns, "transient": transient}
        return self.submit_job("atlas", **spec, model=mapping(model), experiment_id=experiment_id)

    def job(self, job: JobRef, *, timeout: float | None = None) -> Job:
        """A job's state now: ``state``, ``completed`` of ``total``, ``progress`` in [0, 1], ``error``.
        ``timeout`` [s]: this call's, if not the client's."""
        return self._http.call("GET", f"/api/v1/jobs/{job_id(job)}", timeout=timeout)

    def jobs(
        self,
        *,
        state: JobState | None = None,
        experiment_id: int | None = None,
        kind: str | None = None,
        world_id: int | None = None,
        page_size: int = 200,
    ) -> Iterator[Job]:
        """Every job (in ``state``, of ``experiment_id``, of ``kind``, in the stored world
        ``world_id``: each when given), newest first, page after page."""
        params = {"state": state, "experiment_id": experiment_id, "kind": kind, "world_id": world_id}
        return self._http.pages("/api/v1/jobs", params, page_size)

    def wait(
        self,
        job: JobRef,
        *,
        timeout: float | None = None,
        progress: bool = False,
        poll_interval: float = DEFAULT_POLL_INTERVAL,
        check: bool = True,
    ) -> Job:
        """Wait until ``job`` is done, cancelled or failed; returns its final state.

        ``timeout`` [s]: at most this long (None: no limit), then :class:`~parkourlab.JobTimeout`
        (the job goes on running on the service). ``progress``: a progress bar (completed /
        total, elapsed) on standard error when it is a terminal, nothing otherwise.
        ``poll_interval`` [s] between looks. ``check``: a failed or cancelled job raises
        :class:`~parkourlab.JobFailed` (False: it is returned)."""
        ident = job_id(job)
        # Each look a short call of its own: the wait is as long as the job, no request is.
        return wait_for(
            lambda: self.job(ident, timeout=POLL_TIMEOUT),
            timeout=timeout,
            poll_interval=poll_interval,
            progress=progress,
            check=check,
        )

    def results(self, job: JobRef) -> JobResults:
        """A job's results as plain data: MJTF ``levels`` (per zeta0 [l0]: ``trials``, ``mean`` and
        ``std`` jumps to failure, ``outcomes``) and ``missing_zeta0s``; the other kinds'
        ``result``. ``partial`` is true until the job is done."""
        return self._http.call("GET", f"/api/v1/jobs/{job_id(job)}/results")

    def results_frame(self, job: JobRef) -> Any:
        """A job's results as a pandas DataFrame (parkourlab/frames.py: MJTF one row per level, a
        sweep one per point, a gait search one per gait). Needs pandas (ImportError saying so)."""
        frames.require_pandas()
        return frames.results_frame(self.results(job))

    def cancel(self, job: JobRef) -> Job:
        """Cancel a job: a queued one at once, a running one at its next chunk (``cancelling``)."""
        return self._http.call("POST", f"/api/v1/jobs/{job_id(job)}/cancel")


def job_id(job: JobRef) -> int:
    """The id of a job given as its id or as the API's dict."""
    return int(job["id"]) if isinstance(job, Mapping) else int(job)
