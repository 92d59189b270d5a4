"""Waiting by short looks, never one long call: for a job, its state until it is final, with a
progress bar on a terminal; for a service just started, its health until it is ``ok``."""

from __future__ import annotations

import time
from collections.abc import Callable

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TaskProgressColumn, TextColumn, TimeElapsedColumn

from parkourlab.errors import JobFailed, JobTimeout, NotReady, ServiceUnreachable
from parkourlab.types import FINAL_JOB_STATES, Job

POLL_TIMEOUT = 10.0  # [s] for one look at a job or at the service's health: a read of the store, milliseconds


def wait_for(
    fetch: Callable[[], Job],
    *,
    timeout: float | None,
    poll_interval: float,
    progress: bool,
    check: bool,
    console: Console | None = None,
) -> Job:
    """Call ``fetch`` every ``poll_interval`` [s] until the job it returns is done, cancelled or
    failed, and return that last state.

    ``timeout`` [s] (None: no limit): past it, :class:`JobTimeout` (the job goes on on the
    service). ``progress``: a bar of completed / total units on ``console`` (default: standard
    error), shown only when that is a terminal. ``check``: a job that ended failed or cancelled
    raises :class:`JobFailed`."""
    console = console or Console(stderr=True)
    deadline = None if timeout is None else time.monotonic() + timeout
    job = fetch()
    columns = (
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TaskProgressColumn(),
        TimeElapsedColumn(),
        TextColumn("{task.fields[state]}"),
    )
    with Progress(*columns, console=console, disable=not (progress and console.is_terminal)) as bar:
        task = bar.add_task(f"job {job['id']} ({job['kind']})", total=job["total"] or None, state=job["state"])
        while True:
            bar.update(task, completed=job["completed"], total=job["total"] or None, state=job["state"])
            if job["state"] in FINAL_JOB_STATES:
                break
            if deadline is not None and time.monotonic() >= deadline:
                raise JobTimeout(job, timeout)
            pause = poll_interval if deadline is None else min(poll_interval, max(0.0, deadline - time.monotonic()))
            time.sleep(pause)
            job = fetch()
    if check and job["state"] != "done":
        raise JobFailed(job)
    return job


def wait_until_ready(fetch: Callable[[], dict], url: str, *, timeout: float, poll_interval: float) -> dict:
    """Call ``fetch`` (the service's health) every ``poll_interval`` [s] until it answers with status
    ``ok``, and return that answer. A look that finds no service (not listening yet, or no answer
    in time) is followed by another; past ``timeout`` [s], :class:`NotReady` with the last answer."""
    deadline = time.monotonic() + timeout
    health = None
    while True:
        try:
            health = fetch()
            if health["status"] == "ok":
                return health
        except ServiceUnreachable:
            pass
        if time.monotonic() >= deadline:
            raise NotReady(url, health, timeout)
        time.sleep(min(poll_interval, max(0.0, deadline - time.monotonic())))
