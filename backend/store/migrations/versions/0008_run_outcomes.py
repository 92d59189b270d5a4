"""runs: how each ended and was driven, as indexed columns; indexes for the History's sorts

``end_reason`` (what a robot run recorded as its end: "e-stop", "link lost", "robot disarmed
(fell or timed out)", "jumps done", "interrupted: …"; null for simulations), ``loop`` ("open" or
"closed"), ``controller`` ("pid" for a closed loop, else null), ``target`` (a closed loop's height
[m], else null) and ``touchdowns`` (robot and replay runs: the touchdowns recorded, which is what
their ``jumps`` asks for). Each is copied from what the run stored in ``results`` (a robot run's
``end_reason`` and ``closed_loop``; a replay's from the run it replays), as
``repositories.runs.outcome_columns`` does for new runs. Indexes on climb, jumps completed and
duration let a page sorted by one of them read an index instead of sorting every run; one on id
(besides the key) lets SQLite skip to a page deep in the list by id through a narrow index, not
its table of wide rows.

``store_versions`` holds the runs' version, which SQLite triggers move when a run or a tag is added
or deleted or what a list filters or sorts by changes (not a live run's duration alone): the read
workers keep a filter's total and order while it stands still.

Revision ID: 0008
Revises: 0007
Create Date: 2026-12-04 10:00:00
"""

import sqlalchemy as sa
from alembic import op

revision = "0008"
down_revision = "0007"
branch_labels = None
depends_on = None

# What moves the runs' version (SQLite): a run or a tag added or deleted, and a change of what a
# list filters or sorts by — but not a live run's duration alone, which its journal writer updates
# twice a second (a list sorted by duration places a running run by its duration when it started).
LISTED = ("experiment_id", "kind", "status", "created_at", "failure_code", "zeta0", "psi0_deg", "jumps_completed",
          "climb", "notes", "end_reason", "loop", "controller", "target")  # fmt: skip
VERSIONED = [("runs", "INSERT"), ("runs", f"UPDATE OF {', '.join(LISTED)}"), ("runs", "DELETE"),
             ("run_tags", "INSERT"), ("run_tags", "UPDATE"), ("run_tags", "DELETE")]  # fmt: skip
NEW_INDEXES = ("end_reason", "loop", "controller", "target", "climb", "jumps_completed", "duration_s", "id")
END_REASON_LENGTH = 200


def upgrade() -> None:
    # Plain ADD COLUMN (no batch copy of the table: SQLite adds a nullable or defaulted column in place).
    op.add_column("runs", sa.Column("end_reason", sa.String(length=END_REASON_LENGTH), nullable=True))
    op.add_column("runs", sa.Column("loop", sa.String(length=8), server_default="open", nullable=False))
    op.add_column("runs", sa.Column("controller", sa.String(length=16), nullable=True))
    op.add_column("runs", sa.Column("target", sa.Double(), nullable=True))
    op.add_column("runs", sa.Column("touchdowns", sa.Integer(), nullable=True))
    _backfill()
    for column in NEW_INDEXES:
        op.create_index(f"ix_runs_{column}", "runs", [column], unique=False)
    op.create_table(
        "store_versions",
        sa.Column("name", sa.String(length=32), nullable=False),
        sa.Column("version", sa.BigInteger(), nullable=False),
        sa.PrimaryKeyConstraint("name"),
    )
    op.execute("INSERT INTO store_versions (name, version) VALUES ('runs', 0)")
    if op.get_bind().dialect.name == "sqlite":
        for table, change in VERSIONED:
            op.execute(
                f"CREATE TRIGGER {_trigger(table, change)} AFTER {change} ON {table} "
                "BEGIN UPDATE store_versions SET version = version + 1 WHERE name = 'runs'; END"
            )


def _trigger(table: str, change: str) -> str:
    return f"{table}_{change.split()[0].lower()}_bumps_runs_version"


def _backfill() -> None:
    runs = sa.table(
        "runs",
        sa.column("id", sa.Integer),
        sa.column("kind", sa.String),
        sa.column("results", sa.JSON),
        sa.column("end_reason", sa.String),
        sa.column("loop", sa.String),
        sa.column("controller", sa.String),
        sa.column("target", sa.Double),
        sa.column("touchdowns", sa.Integer),
    )
    results = runs.c.results
    target = results[("closed_loop", "target_m")].as_float()
    robot = runs.c.kind == "robot"
    op.execute(
        sa.update(runs)
        .where(robot)
        .values(
            end_reason=sa.func.substr(results["end_reason"].as_string(), 1, END_REASON_LENGTH),
            target=target,
            loop=sa.case((target.is_not(None), "closed"), else_="open"),
            controller=sa.case((target.is_not(None), "pid"), else_=None),
        )
    )
    # A replay analyses a robot run's frames again: it was driven as that run was.
    source = runs.alias("source")
    of_source = source.c.id == results["source_run_id"].as_integer()
    for name in ("loop", "controller", "target"):
        value = sa.select(getattr(source.c, name)).where(of_source).scalar_subquery()
        op.execute(
            sa.update(runs)
            .where(runs.c.kind == "replay")
            .values({name: sa.func.coalesce(value, "open") if name == "loop" else value})
        )
    count = (
        "json_array_length(results, '$.touchdowns')"
        if op.get_bind().dialect.name == "sqlite"
        else "json_array_length(results -> 'touchdowns')"
    )
    op.execute(
        sa.update(runs)
        .where(runs.c.kind.in_(("robot", "replay")))
        .values(touchdowns=sa.func.coalesce(sa.text(count), 0))
    )


def downgrade() -> None:
    if op.get_bind().dialect.name == "sqlite":
        for table, change in VERSIONED:
            op.execute(f"DROP TRIGGER {_trigger(table, change)}")
    op.drop_table("store_versions")
    for column in NEW_INDEXES:
        op.drop_index(f"ix_runs_{column}", table_name="runs")
    with op.batch_alter_table("runs", schema=None) as batch_op:
        for column in ("touchdowns", "target", "controller", "loop", "end_reason"):
            batch_op.drop_column(column)
