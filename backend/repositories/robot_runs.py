"""Robot runs and their journal in the store: the entries a live run appends while it runs, read
back in order and deleted when they are folded into the run, and the runs a service's death left
``running``."""

from __future__ import annotations

from sqlalchemy import delete, select
from sqlalchemy.orm import Session

from backend.store.models import Run, RunJournal


def journal(session: Session, run_id: int) -> list[RunJournal]:
    """The run's journal entries, oldest first."""
    return list(session.scalars(select(RunJournal).where(RunJournal.run_id == run_id).order_by(RunJournal.id)))


def append_journal(session: Session, run_id: int, entries: list[dict]) -> None:
    """Add ``entries`` (each an entry's JSON) to the run's journal (the caller commits)."""
    session.add_all([RunJournal(run_id=run_id, data=data) for data in entries])


def delete_journal(session: Session, run_id: int) -> None:
    """Delete the run's journal entries (the caller commits)."""
    session.execute(delete(RunJournal).where(RunJournal.run_id == run_id))


def running_robot_run_ids(session: Session) -> list[int]:
    """The robot runs still ``running``."""
    return list(session.scalars(select(Run.id).where(Run.kind == "robot", Run.status == "running")))
