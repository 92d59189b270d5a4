"""The Python client of the ParkourLab service: what a batch script uses instead of curl.

It speaks HTTP to the REST API (``/api/v1``, docs/service.md) and nothing else: importing it
loads httpx and rich, never the model, and the service may run on another machine. Answers come
back as plain data (the API's JSON, typed in parkourlab/types.py); errors as typed exceptions
(parkourlab/errors.py). A sketch, against a service started with ``./run.sh``::

    from parkourlab import Client

    with Client() as client:  # http://127.0.0.1:8000, the token from data/api_token
        run = client.create_run([(30, 0.9)], (-0.93, -0.17), jumps=10, tags=["demo"])
        for run in client.runs(tag="demo", zeta0_min=0.85):  # every page
            print(run["id"], run["climb"])
        job = client.wait(client.submit_mjtf([0.86, 0.9], trials=50), progress=True)
        print(client.results(job)["levels"])
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, Literal, Unpack

import httpx

from parkourlab import frames
from parkourlab._http import DEFAULT_TIMEOUT, Http, client_name, find_token, service_url
from parkourlab.bodies import Leg, State, legs, mapping, present, state
from parkourlab.jobs import JobCalls
from parkourlab.types import RUN_FILTERS, Experiment, Page, Run, RunDetail, RunFilters
from parkourlab.waiting import POLL_TIMEOUT, wait_until_ready
from parkourlab.worlds import WorldCalls

RunSort = Literal[
    "-id", "id", "-created_at", "created_at", "-climb", "climb", "-zeta0", "zeta0", "-duration_s", "duration_s"
]
DEFAULT_PAGE_SIZE = 200  # runs fetched per request by the generators; the API allows 1..500


class Client(JobCalls, WorldCalls):
    """A connection to one ParkourLab service.

    Parameters
    ----------
    url: the service, e.g. ``http://lab-pc:8000``; default ``$PARKOUR_URL``, else
        ``http://127.0.0.1:8000`` (``./run.sh``).
    token: the bearer token for changes (create, edit, delete, submit, cancel); default
        ``$PARKOUR_API_TOKEN``, else — for a service on this machine only — the ``api_token`` file
        in ``$PARKOUR_DATA_DIR`` or ``./data``, as ``parkour serve`` writes it. Reads need none.
    timeout: [s] for each HTTP request (not for :meth:`wait`, which has its own). The default, 90 s,
        is longer than the 60 s the service gives a computation before it stops it and answers 503
        saying so: that message reaches the script (:class:`~parkourlab.ServiceUnavailable`)
        instead of a timeout of the client's own.
    name: who this client is to the service (the job queue gives each client a share); default
        ``python@<host>``.
    transport: an ``httpx`` transport to use instead of the network (tests).

    Use it as a context manager, or call :meth:`close`, to close its connections.
    """

    def __init__(
        self,
        url: str | None = None,
        *,
        token: str | None = None,
        timeout: float = DEFAULT_TIMEOUT,
        transport: httpx.BaseTransport | None = None,
        name: str | None = None,
    ) -> None:
        self.url = service_url(url)
        self._http = Http(self.url, token or find_token(self.url), timeout, transport, client_name(name))

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the HTTP connections."""
        self._http.close()

    def __repr__(self) -> str:
        return f"Client({self.url!r}, token={'set' if self._http.token else 'none'})"

    # The service -------------------------------------------------------------------------------
    def health(self) -> dict[str, Any]:
        """``{"status": "ok"|"warming", "warming": [pool, …], "database": "sqlite"|"postgresql",
        "code_version": …, "notices": […]}``: ``warming`` while the service's workers for reads
        and simulations are still loading, just after a start (docs/service.md, "Health")."""
        return self._http.call("GET", "/api/v1/health")

    def wait_ready(self, *, timeout: float = 300.0, poll_interval: float = 0.5) -> dict[str, Any]:
        """Wait until the service answers and its health is ``ok`` (its reads and simulations no
        longer wait for workers loading); returns that health. ``timeout`` [s]: then
        :class:`~parkourlab.NotReady`, naming what still warms. Each look is a short call: a
        service not listening yet, or not answering one look, is looked at again."""

        def look() -> dict[str, Any]:
            return self._http.call("GET", "/api/v1/health", timeout=POLL_TIMEOUT)

        return wait_until_ready(look, self.url, timeout=timeout, poll_interval=poll_interval)

    def controllers(self) -> list[dict[str, Any]]:
        """The closed-loop laws this service knows, in order: ``{"name", "summary", "sets_leg_angle"}``
        each, from its catalog (a control study's ``controllers``, a loop's ``controller``)."""
        return self._http.call("GET", "/api/v1/catalog")["controllers"]

    def token_accepted(self) -> bool:
        """Whether the service accepts this client's token (False without one)."""
        return bool(self._http.token) and self._http.succeeds("GET", "/api/v1/auth")

    # Runs ---------------------------------------------------------------------------------------
    def create_run(
        self,
        controls: Sequence[Leg],
        start: State,
        *,
        jumps: int | None = None,
        tags: Sequence[str] = (),
        model: Mapping[str, Any] | None = None,
        experiment_id: int | None = None,
        trajectory_rate: float | None = None,
        fixed_point: bool = False,
        world_id: int | None = None,
    ) -> RunDetail:
        """Simulate a run on the service and store it; returns it with its results.

        ``controls``: the cyclic schedule, one ``(psi0 [deg], zeta0 [l0])`` per leg (one pair:
        symmetric; two: left, right). ``start``: the section state ``(xdot, ydot)`` [sqrt(g l0)],
        xdot < 0. ``jumps``: how many (None: the service's default). ``model``: ``{"preset":
        "paper"}`` and nondimensional overrides (``alpha``, ``d_hat``, ``c_zeta``, ``c_psi``,
        ``mu``; docs/model.md §1). ``trajectory_rate``: also store the path, samples per
        sqrt(l0/g). ``fixed_point``: also find the gait near ``start``. ``world_id``: climb that
        stored world (:meth:`create_world`; its results are ``parkour climb``'s touchdowns) instead
        of parallel walls."""
        body = {
            "controls": legs(controls),
            "start": state(start),
            "jumps": jumps,
            "tags": list(tags),
            "model": mapping(model),
            "experiment_id": experiment_id,
            "trajectory_rate": trajectory_rate,
            "fixed_point": fixed_point,
            "world_id": world_id,
        }
        return self._http.call("POST", "/api/v1/runs", body=present(body))

    def runs(
        self, *, sort: RunSort = "-id", page_size: int = DEFAULT_PAGE_SIZE, **filters: Unpack[RunFilters]
    ) -> Iterator[Run]:
        """Every run matching ``filters`` (:class:`~parkourlab.types.RunFilters`: ``tag``,
        ``experiment_id``, ``zeta0_min`` …), page after page, ``page_size`` per request, in
        ``sort`` order (``-id``: newest first; ``-climb``: best first). A misspelt filter is a
        TypeError at once, before any request."""
        run_filters(filters)
        return self._all_runs(sort, page_size, filters)

    def _all_runs(self, sort: RunSort, page_size: int, filters: RunFilters) -> Iterator[Run]:
        cursor: int | None = None
        offset = 0
        while True:
            page = self.runs_page(limit=page_size, cursor=cursor, offset=offset, sort=sort, **filters)
            yield from page["items"]
            if page.get("next_cursor") is None:
                return
            if sort.lstrip("-") == "id":  # keyset pages: the last id; other sorts: the next offset
                cursor = page["next_cursor"]
            else:
                offset = page["next_cursor"]

    def runs_page(
        self,
        *,
        limit: int = 50,
        cursor: int | None = None,
        offset: int = 0,
        sort: RunSort = "-id",
        **filters: Unpack[RunFilters],
    ) -> Page[Run]:
        """One page of runs, as the API gives it (``items``, ``next_cursor``): ``limit`` in 1..500;
        sorted by id, ``cursor`` is the previous page's ``next_cursor``; sorted otherwise, ``offset``."""
        params = {"limit": limit, "cursor": cursor, "offset": offset or None, "sort": sort}
        return self._http.call("GET", "/api/v1/runs", params=params | run_filters(filters))

    def run(self, run_id: int) -> RunDetail:
        """One run with its results."""
        return self._http.call("GET", f"/api/v1/runs/{run_id}")

    def trajectory(self, run_id: int) -> dict[str, Any]:
        """A run's stored path: ``{"units", "column_units", "columns": {name: [values]}}`` (a
        simulated run's nondimensional time, x, y, …; a robot run's in SI). NotFound if it has none."""
        return self._http.call("GET", f"/api/v1/runs/{run_id}/trajectory")

    def update_run(self, run_id: int, *, tags: Sequence[str] | None = None, notes: str | None = None) -> Run:
        """Replace a run's tags and/or notes (None: left as they are); the only fields that change."""
        body = present({"tags": None if tags is None else list(tags), "notes": notes})
        return self._http.call("PATCH", f"/api/v1/runs/{run_id}", body=body)

    def delete_run(self, run_id: int) -> None:
        """Delete a run."""
        self._http.call("DELETE", f"/api/v1/runs/{run_id}")

    def aggregate(self, by: str = "zeta0", *, bins: int | None = None, **filters: Unpack[RunFilters]) -> dict[str, Any]:
        """Runs grouped ``by`` zeta0, psi0_deg, alpha, kind, failure_code, experiment_id or tag
        (continuous ones in ``bins`` equal bins): per group ``runs`` and the ``climb`` [l0] and
        ``jumps_completed`` statistics (mean, std, min, max), computed by the service."""
        params = {"by": by, "bins": bins} | run_filters(filters)
        return self._http.call("GET", "/api/v1/runs/aggregate", params=params)

    def compare(self, run_ids: Sequence[int], *, only_differences: bool = True) -> dict[str, Any]:
        """2 to 50 runs side by side as flat records (``fields``, ``differing``, ``runs``)."""
        params = {"ids": list(run_ids), "only_differences": only_differences}
        return self._http.call("GET", "/api/v1/runs/compare", params=params)

    def runs_frame(self, **filters: Unpack[RunFilters]) -> Any:
        """Every run matching ``filters`` as a pandas DataFrame indexed by run id, one flat column
        per field (``climb`` [l0], ``model.alpha``, ``leg0.psi0_deg`` [deg], ``leg0.zeta0`` [l0],
        ``start_xdot`` …: the service's JSON export). Needs pandas (ImportError saying so)."""
        frames.require_pandas()
        records = self._http.call("GET", "/api/v1/runs/export", params={"format": "json"} | run_filters(filters))
        return frames.runs_frame(records)

    # Exports -----------------------------------------------------------------------------------
    def export_runs(
        self, path: str | Path, *, format: Literal["csv", "json"] | None = None, **filters: Unpack[RunFilters]
    ) -> Path:
        """Every run matching ``filters`` written to ``path`` as CSV or JSON (``format``; default
        from the file's suffix, else CSV): the service's export, streamed to the file."""
        path = Path(path)
        format = format or ("json" if path.suffix.lower() == ".json" else "csv")
        return self._http.download("/api/v1/runs/export", path, {"format": format} | run_filters(filters))

    def export_mcap(self, run_id: int, path: str | Path) -> Path:
        """A run as an MCAP recording (Foxglove, Rerun) written to ``path``: a robot or replay run,
        or a simulated run stored with its path (``trajectory_rate``); Conflict for one stored
        without (its touchdowns are in :meth:`run`) or still running."""
        return self._http.download(f"/api/v1/runs/{run_id}/export.mcap", Path(path))

    # Experiments -------------------------------------------------------------------------------
    def create_experiment(
        self, name: str, *, description: str = "", notes: str = "", tags: Sequence[str] = ()
    ) -> Experiment:
        """A new experiment, to file runs and jobs under (their ``experiment_id``)."""
        body = {"name": name, "description": description, "notes": notes, "tags": list(tags)}
        return self._http.call("POST", "/api/v1/experiments", body=body)

    def experiments(self, *, page_size: int = DEFAULT_PAGE_SIZE) -> Iterator[Experiment]:
        """Every experiment, newest first, page after page."""
        return self._http.pages("/api/v1/experiments", {}, page_size)

    def experiment(self, experiment_id: int) -> Experiment:
        return self._http.call("GET", f"/api/v1/experiments/{experiment_id}")

    def update_experiment(
        self,
        experiment_id: int,
        *,
        name: str | None = None,
        description: str | None = None,
        notes: str | None = None,
        tags: Sequence[str] | None = None,
    ) -> Experiment:
        """Change an experiment's fields; those left None stay as they are."""
        body = {"name": name, "description": description, "notes": notes, "tags": None if tags is None else list(tags)}
        return self._http.call("PATCH", f"/api/v1/experiments/{experiment_id}", body=present(body))

    def delete_experiment(self, experiment_id: int) -> None:
        """Delete an experiment; Conflict while it still has runs."""
        self._http.call("DELETE", f"/api/v1/experiments/{experiment_id}")

    # Calibrations ------------------------------------------------------------------------------
    def calibrations(self) -> list[dict[str, Any]]:
        """The stored calibrations (model fits to robot runs, docs/calibration.md)."""
        return self._http.call("GET", "/api/v1/calibrations")["items"]

    def calibration(self, name: str) -> dict[str, Any]:
        return self._http.call("GET", f"/api/v1/calibrations/{name}")

    def create_calibration(self, runs: Sequence[int], name: str) -> dict[str, Any]:
        """Fit the model to robot or replay ``runs`` and store it as preset ``name`` (usable as
        ``model={"preset": name}``)."""
        return self._http.call("POST", "/api/v1/calibrations", body={"runs": list(runs), "name": name})

    def delete_calibration(self, name: str) -> None:
        self._http.call("DELETE", f"/api/v1/calibrations/{name}")


def run_filters(filters: Mapping[str, Any]) -> dict[str, Any]:
    """``filters`` checked against the API's run filters: the API ignores a query parameter it does
    not know, so a misspelt filter would match every run; here it is a TypeError naming it."""
    unknown = sorted(set(filters) - RUN_FILTERS)
    if unknown:
        raise TypeError(f"unknown run filter {', '.join(unknown)}: the filters are {', '.join(sorted(RUN_FILTERS))}")
    return dict(filters)
