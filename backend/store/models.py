"""The stored records (SQLAlchemy 2.x, typed): experiments contain runs; MJTF jobs contain trials,
the other kinds of job keep their result as JSON.

Filterable and sortable run attributes (kind, status, the first leg's controls, alpha, failure,
climb, jumps, duration, how it ended and was driven) are columns with indexes; the full
parameters, schedule and results are JSON, and trajectories a compressed binary, so a run is one
row however long it is.
"""

from __future__ import annotations

import datetime
from typing import ClassVar

from sqlalchemy import (
    JSON,
    BigInteger,
    DateTime,
    ForeignKey,
    Index,
    LargeBinary,
    String,
    Text,
    TypeDecorator,
    UniqueConstraint,
)
from sqlalchemy.orm import DeclarativeBase, Mapped, column_property, mapped_column, relationship


def utcnow() -> datetime.datetime:
    return datetime.datetime.now(datetime.UTC)


class UTCDateTime(TypeDecorator):
    """Timestamps in UTC, timezone-aware on the way out too (SQLite stores them without one)."""

    impl = DateTime(timezone=True)
    cache_ok = True

    def process_bind_param(self, value, _dialect):
        # SQLite keeps the wall time and drops the offset: 14:00+02:00 must go in (or be compared) as 12:00.
        if value is not None and value.tzinfo is not None:
            return value.astimezone(datetime.UTC)
        return value

    def process_result_value(self, value, _dialect):
        if value is not None and value.tzinfo is None:
            return value.replace(tzinfo=datetime.UTC)
        return value


class Base(DeclarativeBase):
    type_annotation_map: ClassVar = {dict: JSON, list: JSON, datetime.datetime: UTCDateTime}


class Experiment(Base):
    __tablename__ = "experiments"

    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(200))
    description: Mapped[str] = mapped_column(Text, default="")
    notes: Mapped[str] = mapped_column(Text, default="")
    tags: Mapped[list] = mapped_column(default=list)
    created_at: Mapped[datetime.datetime] = mapped_column(default=utcnow, index=True)
    updated_at: Mapped[datetime.datetime] = mapped_column(default=utcnow, onupdate=utcnow)

    runs: Mapped[list[Run]] = relationship(back_populates="experiment")


class World(Base):
    """A world (docs/model.md §8) the lab stored by name: the §8 JSON as it was posted (coordinates
    exact), where it came from (``source``: "posted", "named:staircase", "random:7"), who stored it
    and when. Runs, robot runs and jobs in it refer to it (``world_id``); none: parallel walls."""

    __tablename__ = "worlds"

    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(200), unique=True)
    document: Mapped[dict]
    source: Mapped[str] = mapped_column(String(200))
    created_at: Mapped[datetime.datetime] = mapped_column(default=utcnow, index=True)
    created_by: Mapped[str | None] = mapped_column(String(64))


class Run(Base):
    __tablename__ = "runs"

    # Indexed besides being the key: SQLite orders by id through its table, whose rows are wide,
    # and a page deep in the list by id read every row before it (36 ms at 100,000 runs; 1 ms now).
    id: Mapped[int] = mapped_column(primary_key=True, index=True)
    experiment_id: Mapped[int | None] = mapped_column(ForeignKey("experiments.id", ondelete="RESTRICT"), index=True)
    kind: Mapped[str] = mapped_column(String(16), index=True)  # sim | robot | replay
    # done | failed (a physical failure is "done"); a live robot run is "running" from its start,
    # and "interrupted" if the service died during it (its journal is then folded into it).
    status: Mapped[str] = mapped_column(String(16), index=True)
    created_at: Mapped[datetime.datetime] = mapped_column(default=utcnow, index=True)
    duration_s: Mapped[float] = mapped_column(default=0.0, index=True)
    code_version: Mapped[str] = mapped_column(String(64))
    model: Mapped[dict]  # nondimensional parameters
    controls: Mapped[list]  # [[psi0_deg, zeta0], ...]
    start_state: Mapped[list]
    jumps: Mapped[int]
    # Indexed copies for filtering.
    alpha: Mapped[float] = mapped_column(index=True)
    psi0_deg: Mapped[float]  # first leg; indexed with zeta0 (below)
    zeta0: Mapped[float] = mapped_column(index=True)  # first leg
    failure_code: Mapped[str | None] = mapped_column(String(32), index=True)
    jumps_completed: Mapped[int] = mapped_column(index=True)
    climb: Mapped[float] = mapped_column(index=True)  # total height gain [l0]
    results: Mapped[dict]  # section states, rises, failure, fixed point
    trajectory: Mapped[bytes | None] = mapped_column(LargeBinary)  # zlib'd .npz of the sampled path
    notes: Mapped[str] = mapped_column(Text, default="", server_default="")  # the one thing that changes, with tags
    # How it ended and how it was driven (migration 0008), copied from its results by
    # repositories.runs.outcome_columns: what a robot run recorded as its end ("e-stop", "link
    # lost", "robot disarmed (fell or timed out)", "jumps done", ...; None for simulations), open or
    # closed loop, the controller of a closed loop ("pid") and its height target [m].
    end_reason: Mapped[str | None] = mapped_column(String(200), index=True)
    loop: Mapped[str] = mapped_column(String(8), default="open", server_default="open", index=True)
    controller: Mapped[str | None] = mapped_column(String(16), index=True)
    target: Mapped[float | None] = mapped_column(index=True)  # [m]
    touchdowns: Mapped[int | None]  # robot and replay runs: touchdowns recorded (what their jumps count)
    created_by: Mapped[str | None] = mapped_column(String(64))  # the person (null: stored before people had names)
    notes_by: Mapped[str | None] = mapped_column(String(64))  # who last wrote its notes or tags
    # The world it ran in (migration 0013); None: parallel walls, as every run before worlds.
    world_id: Mapped[int | None] = mapped_column(ForeignKey("worlds.id"), index=True)

    experiment: Mapped[Experiment | None] = relationship(back_populates="runs")
    run_tags: Mapped[list[RunTag]] = relationship(cascade="all, delete-orphan", lazy="selectin")
    # Whether it has a trajectory, without loading it: lists and exports defer the blob and results.
    has_trajectory: Mapped[bool] = column_property(trajectory.is_not(None))

    # psi0 and zeta0 ranges together read this index alone; psi0 alone uses its prefix.
    __table_args__ = (Index("ix_runs_psi0_deg_zeta0", "psi0_deg", "zeta0"),)

    @property
    def tags(self) -> list[str]:
        return sorted(tag.tag for tag in self.run_tags)


class RunJournal(Base):
    """A live robot run's data, appended while it runs (frames, touchdowns, commands, telemetry
    and link transitions since the previous entry): what a crash cannot take away. Folded into
    the run and deleted when the run ends, or at the next start if the service died first."""

    __tablename__ = "run_journal"

    id: Mapped[int] = mapped_column(primary_key=True)
    run_id: Mapped[int] = mapped_column(ForeignKey("runs.id", ondelete="CASCADE"), index=True)
    written_at: Mapped[datetime.datetime] = mapped_column(default=utcnow)
    data: Mapped[dict]


class RunTag(Base):
    """One row per (run, tag): tags filter through an index instead of scanning JSON."""

    __tablename__ = "run_tags"

    run_id: Mapped[int] = mapped_column(ForeignKey("runs.id", ondelete="CASCADE"), primary_key=True)
    tag: Mapped[str] = mapped_column(String(64), primary_key=True)

    __table_args__ = (Index("ix_run_tags_tag", "tag", "run_id"),)


class StoreVersion(Base):
    """How often a part of the store has changed: ``runs`` counts the changes of runs and their tags
    that a list can see — a run or tag added or deleted, a change of what lists filter or sort by —
    bumped by SQLite triggers (migration 0008); ``runs_reshaped`` only those that are not to the
    newest run (migration 0010). The run list's read workers keep the orders they read while
    ``runs`` stands still and the totals' bases while ``runs_reshaped`` does
    (``repositories.run_list_cache``); other commits — a job's trials, a live run's journal
    entries and its duration — leave them valid. PostgreSQL has the table but no triggers (its
    counts are not kept)."""

    __tablename__ = "store_versions"

    name: Mapped[str] = mapped_column(String(32), primary_key=True)
    version: Mapped[int] = mapped_column(BigInteger, default=0)


class Job(Base):
    """A batch job (MJTF trials, a sweep, a basin or a gait search); it lives here, not in memory,
    so a restart resumes it."""

    __tablename__ = "jobs"

    id: Mapped[int] = mapped_column(primary_key=True)
    experiment_id: Mapped[int | None] = mapped_column(ForeignKey("experiments.id", ondelete="RESTRICT"), index=True)
    kind: Mapped[str] = mapped_column(String(16))  # mjtf | sweep | basin | gaits
    spec: Mapped[dict]
    state: Mapped[str] = mapped_column(String(16), index=True)  # queued running cancelling cancelled done failed
    total: Mapped[int]
    completed: Mapped[int] = mapped_column(default=0)
    error: Mapped[str | None] = mapped_column(Text)
    result: Mapped[dict | None]  # studies other than MJTF: their result once done (MJTF's are its trials)
    code_version: Mapped[str] = mapped_column(String(64))
    created_at: Mapped[datetime.datetime] = mapped_column(default=utcnow, index=True)
    updated_at: Mapped[datetime.datetime] = mapped_column(default=utcnow, onupdate=utcnow)
    started_at: Mapped[datetime.datetime | None]
    finished_at: Mapped[datetime.datetime | None]
    submitted_by: Mapped[str | None] = mapped_column(String(64))  # the person: the queue's shares are per person
    submitted_via: Mapped[str | None] = mapped_column(String(64))  # the tool (X-Parkour-Client), a label only
    world_id: Mapped[int | None] = mapped_column(ForeignKey("worlds.id"), index=True)

    trials: Mapped[list[Trial]] = relationship(back_populates="job", cascade="all, delete-orphan")
    chunks: Mapped[list[JobChunk]] = relationship(back_populates="job", cascade="all, delete-orphan")


class Trial(Base):
    """One MJTF trial; (job, level, index) is its idempotent key."""

    __tablename__ = "trials"

    id: Mapped[int] = mapped_column(primary_key=True)
    job_id: Mapped[int] = mapped_column(ForeignKey("jobs.id", ondelete="CASCADE"))
    level: Mapped[int]
    index: Mapped[int]
    zeta0: Mapped[float]
    seed: Mapped[int] = mapped_column(BigInteger)  # 32-bit unsigned: beyond PostgreSQL's INTEGER
    jumps: Mapped[int]
    failure_code: Mapped[str | None] = mapped_column(String(32))

    job: Mapped[Job] = relationship(back_populates="trials")

    __table_args__ = (UniqueConstraint("job_id", "level", "index", name="uq_trials_key"),)


class JobChunk(Base):
    """One finished chunk of a chunked job (a foothold study's world, a block of trials in a world):
    its JSON result, stored as it finished, so that a restart computes only the chunks missing.
    (job, index) is its idempotent key."""

    __tablename__ = "job_chunks"

    job_id: Mapped[int] = mapped_column(ForeignKey("jobs.id", ondelete="CASCADE"), primary_key=True)
    index: Mapped[int] = mapped_column(primary_key=True)
    result: Mapped[dict]

    job: Mapped[Job] = relationship(back_populates="chunks")


class ModelPreset(Base):
    """A named model fitted to robot runs (``parkour calibrate``): a preset beside the built-in ones.

    ``base`` is the built-in preset it refines; ``physical`` its fitted parameters in SI
    (:class:`sim_core.model.params.PhysicalParams` fields), ``offsets`` the legs' servo offsets, ``fit``
    the calibration's report (standard errors, correlation, residuals, noise) and ``runs`` the ids
    it was fitted to — its provenance with ``created_at`` and ``code_version``.
    """

    __tablename__ = "model_presets"

    id: Mapped[int] = mapped_column(primary_key=True)
    name: Mapped[str] = mapped_column(String(64), unique=True)
    base: Mapped[str] = mapped_column(String(64))
    physical: Mapped[dict]
    offsets: Mapped[dict]
    fit: Mapped[dict]
    runs: Mapped[list]
    code_version: Mapped[str] = mapped_column(String(64))
    created_at: Mapped[datetime.datetime] = mapped_column(default=utcnow, index=True)


# What migrations make beside the models' tables, which the models do not describe: History's
# search index (0012: SQLite's FTS5 table and its shadow tables, PostgreSQL's trigram indexes).
UNMODELLED = ("run_search", "ix_runs_notes_trgm", "ix_run_tags_tag_trgm")


def modelled(_object, name, _type, _reflected, _compare_to) -> bool:
    """Alembic's ``include_object``: whether the models describe ``name`` (see :data:`UNMODELLED`)."""
    return not (name or "").startswith(UNMODELLED)
