"""store_versions: ``runs_reshaped``, the changes to the run list other than what its newest run adds

``runs`` (migration 0008) moves whenever a list could see a change. ``runs_reshaped`` moves only
for the changes that can alter what runs older than the newest one count towards a total: a run
deleted, a run or tag added or changed other than the newest run's (id equal to the largest id
at the time). A new run, its tags, and later changes to it while it is still the newest leave it
alone, so a read worker's totals stay valid under them: each is its count below an id, plus the
runs since then counted afresh (``repositories.run_list_cache``). SQLite only, like 0008's
triggers; PostgreSQL keeps no counts.

Revision ID: 0010
Revises: 0009
Create Date: 2026-12-03 20:15:00
"""

from alembic import op

revision = "0010"
down_revision = "0009"
branch_labels = None
depends_on = None

# The columns whose change a list sees (migration 0008's LISTED).
LISTED = ("experiment_id", "kind", "status", "created_at", "failure_code", "zeta0", "psi0_deg", "jumps_completed",
          "climb", "notes", "end_reason", "loop", "controller", "target")  # fmt: skip
_OLDER = "(SELECT MAX(id) FROM runs)"  # the newest run's id when the trigger fires
# (trigger name, event, WHEN condition or None: always)
TRIGGERS = [
    ("runs_insert_reshapes", "INSERT ON runs", f"NEW.id < {_OLDER}"),
    ("runs_update_reshapes", f"UPDATE OF id, {', '.join(LISTED)} ON runs", f"OLD.id < {_OLDER} OR NEW.id <> OLD.id"),
    ("runs_delete_reshapes", "DELETE ON runs", None),
    ("run_tags_insert_reshapes", "INSERT ON run_tags", f"NEW.run_id < {_OLDER}"),
    ("run_tags_update_reshapes", "UPDATE ON run_tags", f"OLD.run_id < {_OLDER} OR NEW.run_id < {_OLDER}"),
    ("run_tags_delete_reshapes", "DELETE ON run_tags", f"OLD.run_id < {_OLDER}"),
]


def upgrade() -> None:
    op.execute("INSERT INTO store_versions (name, version) VALUES ('runs_reshaped', 0)")
    if op.get_bind().dialect.name != "sqlite":
        return
    for name, event, condition in TRIGGERS:
        when = f" WHEN {condition}" if condition else ""
        op.execute(
            f"CREATE TRIGGER {name} AFTER {event}{when} "
            "BEGIN UPDATE store_versions SET version = version + 1 WHERE name = 'runs_reshaped'; END"
        )


def downgrade() -> None:
    if op.get_bind().dialect.name == "sqlite":
        for name, _, _ in TRIGGERS:
            op.execute(f"DROP TRIGGER {name}")
    op.execute("DELETE FROM store_versions WHERE name = 'runs_reshaped'")
