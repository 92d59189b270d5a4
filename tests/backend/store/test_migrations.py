"""Migrations build the models' schema from an empty database, and nothing is left unmigrated: on
SQLite and on PostgreSQL."""

from alembic.autogenerate import compare_metadata
from alembic.migration import MigrationContext
from sqlalchemy import inspect, text

from backend.store.database import make_engine, migrate, sqlite_url
from backend.store.models import Base, modelled


def test_upgrade_from_empty_matches_the_models(empty_database_url):
    engine = make_engine(empty_database_url)
    migrate(engine)
    assert set(inspect(engine).get_table_names()) >= {"experiments", "runs", "run_tags", "jobs", "trials"}
    with engine.connect() as connection:
        context = MigrationContext.configure(connection, opts={"include_object": modelled})  # not the search index
        differences = compare_metadata(context, Base.metadata)
    assert differences == [], f"models changed without a migration: {differences}"
    migrate(engine)  # idempotent at head
    engine.dispose()


def test_sqlite_runs_in_wal_mode_with_foreign_keys(tmp_path):
    engine = make_engine(sqlite_url(tmp_path))
    with engine.connect() as connection:
        assert connection.exec_driver_sql("PRAGMA journal_mode").scalar() == "wal"
        assert connection.exec_driver_sql("PRAGMA foreign_keys").scalar() == 1


def _row_after_upgrade(url: str, revision: str, insert: str, select: str) -> tuple:
    """Migrate an empty database to ``revision``, store a row the old way, upgrade to head, read it back."""
    engine = make_engine(url)
    migrate(engine, revision)
    with engine.begin() as connection:
        connection.exec_driver_sql(insert)
    migrate(engine)
    try:
        with engine.connect() as connection:
            return tuple(connection.exec_driver_sql(select).one())
    finally:
        engine.dispose()


def test_upgrade_from_the_previous_revision_keeps_the_data(empty_database_url):
    insert = (
        "INSERT INTO jobs (kind, spec, state, total, completed, code_version, created_at, updated_at) "
        "VALUES ('mjtf', '{}', 'done', 8, 8, 'old', '2026-01-01 00:00:00', '2026-01-01 00:00:00')"
    )
    row = _row_after_upgrade(empty_database_url, "0001", insert, "SELECT kind, total, code_version, result FROM jobs")
    assert row == ("mjtf", 8, "old", None)


def test_runs_stored_before_notes_get_empty_notes(empty_database_url):
    insert = (
        "INSERT INTO runs (kind, status, created_at, duration_s, code_version, model, controls, start_state, "
        "jumps, alpha, psi0_deg, zeta0, jumps_completed, climb, results) VALUES ('sim', 'done', "
        "'2026-01-01 00:00:00', 0.1, 'old', '{}', '[[30, 0.9]]', '[-0.9, -0.2]', 4, 77.6, 30, 0.9, 4, 1.2, '{}')"
    )
    row = _row_after_upgrade(empty_database_url, "0003", insert, "SELECT code_version, climb, notes FROM runs")
    assert row == ("old", 1.2, "")


RUN_COLUMNS = (
    "INSERT INTO runs (id, kind, status, created_at, duration_s, code_version, model, controls, start_state, jumps, "
    "alpha, psi0_deg, zeta0, jumps_completed, climb, results) VALUES "
)
OLD_RUN = "({id}, '{kind}', '{status}', '2026-01-01 00:00:00', 0.1, 'old', '{{}}', '[[30, 0.9]]', '[-0.9, -0.2]', 15, "
OLD_RUN += "77.6, 30, 0.9, 14, 1.2, '{results}')"
CLOSED = '{"target_m": 0.55, "kp": 0.04, "ki": 0.0, "kd": 0.02, "zeta0_min": 0.8, "zeta0_max": 0.98}'
OLD_RUNS = [
    dict(id=1, kind="sim", status="done", results='{"rises": [0.3], "failure": null}'),
    dict(id=2, kind="robot", status="failed",
         results=f'{{"end_reason": "e-stop", "closed_loop": {CLOSED}, "touchdowns": [{{}}, {{}}, {{}}]}}'),
    dict(id=3, kind="robot", status="done",
         results='{"end_reason": "jumps done", "closed_loop": null, "touchdowns": []}'),
    dict(id=4, kind="replay", status="done", results='{"source_run_id": 2, "touchdowns": [{}, {}]}'),
    dict(id=5, kind="replay", status="done", results='{"source_run_id": 99, "touchdowns": [{}]}'),  # source deleted
    dict(id=6, kind="robot", status="running", results='{"end_reason": null, "closed_loop": null}'),
]  # fmt: skip


def test_runs_stored_before_0008_get_their_outcome_columns(empty_database_url):
    """Migration 0008 copies how each stored run ended and was driven from its results: a robot
    run's end reason and closed loop, a replay's loop from the run it replays, the touchdowns."""
    engine = make_engine(empty_database_url)
    migrate(engine, "0007")
    with engine.begin() as connection:
        connection.exec_driver_sql(RUN_COLUMNS + ", ".join(OLD_RUN.format(**run) for run in OLD_RUNS))
    migrate(engine)
    try:
        with engine.connect() as connection:
            rows = connection.exec_driver_sql(
                "SELECT id, end_reason, loop, controller, target, touchdowns FROM runs ORDER BY id"
            ).all()
    finally:
        engine.dispose()
    assert [tuple(row) for row in rows] == [
        (1, None, "open", None, None, None),
        (2, "e-stop", "closed", "pid", 0.55, 3),
        (3, "jumps done", "open", None, None, 0),
        (4, None, "closed", "pid", 0.55, 2),
        (5, None, "open", None, None, 1),
        (6, None, "open", None, None, 0),
    ]


def test_the_search_index_is_built_and_kept(empty_database_url):
    """Migration 0012: History's search reads an index (SQLite's FTS5 trigram table, kept by
    triggers; PostgreSQL's pg_trgm indexes), filled from the runs stored before it."""
    from sqlalchemy import text

    engine = make_engine(empty_database_url)
    migrate(engine, "0011")
    with engine.begin() as connection:
        connection.execute(text(
            "INSERT INTO runs (id, kind, status, created_at, duration_s, code_version, model, controls, start_state, "
            "jumps, alpha, psi0_deg, zeta0, jumps_completed, climb, results, notes, loop) VALUES (7, 'sim', 'done', "
            "'2026-12-01 00:00:00', 1, 'x', '{}', '[]', '[]', 1, 15, 30, 0.9, 1, 1, '{}', 'Slipped twice', 'open')"
        ))  # fmt: skip
        connection.execute(text("INSERT INTO run_tags (run_id, tag) VALUES (7, 'wet-wall')"))
    migrate(engine)
    with engine.connect() as connection:
        if engine.dialect.name == "sqlite":
            found = "SELECT rowid FROM run_search WHERE run_search MATCH :q"
            assert connection.execute(text(found), {"q": '"slipped"'}).scalars().all() == [7], "filled at migration"
            assert connection.execute(text(found), {"q": '"wet-wall"'}).scalars().all() == [7]
        else:
            names = set(connection.execute(text("SELECT indexname FROM pg_indexes")).scalars())
            assert {"ix_runs_notes_trgm", "ix_run_tags_tag_trgm"} <= names
            # The search as History asks it can read them (in an OR with the tags' condition it could not).
            from sqlalchemy import select

            from backend.repositories.run_filters import RunFilter, filtered
            from backend.store.models import Run

            query = filtered(select(Run.id), RunFilter(q="slipped"))
            connection.exec_driver_sql("SET enable_seqscan = off")  # a table of one run: else it scans anyway
            statement = query.compile(engine, compile_kwargs={"literal_binds": True})
            plan = "\n".join(connection.exec_driver_sql(f"EXPLAIN {statement}").scalars())
            assert "Bitmap Index Scan on ix_runs_notes_trgm" in plan, plan  # the notes: never every run's
            assert connection.execute(query).scalars().all() == [7]
    engine.dispose()


def test_runs_and_jobs_stored_before_worlds_are_on_parallel_walls(empty_database_url):
    """Migration 0013: the worlds table, and ``world_id`` null on every run and job stored before."""
    run = RUN_COLUMNS + OLD_RUN.format(id=1, kind="sim", status="done", results="{}")
    assert _row_after_upgrade(empty_database_url, "0012", run, "SELECT id, world_id FROM runs") == (1, None)


def test_the_search_index_still_follows_notes_after_worlds(empty_database_url):
    """0013 adds ``runs.world_id`` in place: the triggers that keep History's search (0012) stay."""
    engine = make_engine(empty_database_url)
    migrate(engine)
    try:
        with engine.begin() as connection:
            connection.exec_driver_sql(RUN_COLUMNS + OLD_RUN.format(id=7, kind="sim", status="done", results="{}"))
            connection.exec_driver_sql("UPDATE runs SET notes = 'slipped on the third foothold' WHERE id = 7")
        with engine.connect() as connection:
            if engine.dialect.name == "sqlite":
                found = connection.execute(text("SELECT rowid FROM run_search WHERE notes LIKE '%third%'")).all()
            else:
                found = connection.execute(text("SELECT id FROM runs WHERE notes ILIKE '%third%'")).all()
    finally:
        engine.dispose()
    assert [tuple(row) for row in found] == [(7,)]
