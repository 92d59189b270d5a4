"""parkourlab/waiting.py: a wait polls until the job is final, draws its bar only on a terminal,
and stops at its timeout; a wait for the service until its health is ok."""

import io

import pytest
from rich.console import Console

from parkourlab.errors import JobFailed, JobTimeout, NotReady, ServiceUnreachable
from parkourlab.waiting import wait_for, wait_until_ready

URL = "http://127.0.0.1:8000"


def job(state: str, completed: int, total: int = 4) -> dict:
    return {"id": 7, "kind": "mjtf", "state": state, "completed": completed, "total": total, "error": None}


def states(*jobs: dict):
    answers = iter(jobs)
    return lambda: next(answers)


def console(terminal: bool) -> tuple[Console, io.StringIO]:
    out = io.StringIO()
    return Console(file=out, force_terminal=terminal, width=100), out


def test_polls_until_done_with_a_bar_on_a_terminal():
    screen, out = console(terminal=True)
    fetch = states(job("queued", 0), job("running", 2), job("done", 4))
    final = wait_for(fetch, timeout=None, poll_interval=0, progress=True, check=True, console=screen)
    assert final["state"] == "done"
    assert "job 7 (mjtf)" in out.getvalue() and "4/4" in out.getvalue()


def test_no_bar_when_not_a_terminal_or_not_asked():
    for terminal, progress in ((False, True), (True, False)):
        screen, out = console(terminal)
        fetch = states(job("running", 1), job("done", 4))
        wait_for(fetch, timeout=None, poll_interval=0, progress=progress, check=True, console=screen)
        assert out.getvalue() == ""


def test_timeout():
    def never_done() -> dict:
        return job("running", 1)

    with pytest.raises(JobTimeout, match=r"job 7 \(mjtf\) still running after 0.05 s \(1 of 4 done\)"):
        wait_for(never_done, timeout=0.05, poll_interval=0.01, progress=False, check=True)


def test_failed_jobs_raise_unless_told_not_to():
    failed = job("failed", 1) | {"error": "worker died"}
    with pytest.raises(JobFailed, match="job 7 \\(mjtf\\) ended failed: worker died"):
        wait_for(states(failed), timeout=None, poll_interval=0, progress=False, check=True)
    assert wait_for(states(failed), timeout=None, poll_interval=0, progress=False, check=False) == failed


def health(status: str, *warming: str) -> dict:
    return {"status": status, "warming": list(warming), "database": "sqlite", "code_version": "x", "notices": []}


def test_wait_until_ready_looks_again_at_a_service_not_up_or_warming():
    def not_listening() -> dict:
        raise ServiceUnreachable(URL, "connection refused")

    answers = iter([not_listening, lambda: health("warming", "reads", "quick"), lambda: health("ok", "jobs")])
    ready = wait_until_ready(lambda: next(answers)(), URL, timeout=60, poll_interval=0)
    assert ready["status"] == "ok" and ready["warming"] == ["jobs"], "the job worker may still load"


def test_wait_until_ready_times_out_naming_what_still_warms():
    with pytest.raises(NotReady, match=r"not ready after 0.05 s: still warming \(quick\)"):
        wait_until_ready(lambda: health("warming", "quick"), URL, timeout=0.05, poll_interval=0.01)

    def never() -> dict:
        raise ServiceUnreachable(URL, "connection refused")

    with pytest.raises(NotReady, match="it did not answer"):
        wait_until_ready(never, URL, timeout=0.05, poll_interval=0.01)
