"""The stored records (backend/store/models.py) on a migrated SQLite file: timestamps in UTC both
ways, a run's tags and trajectory flag, what deleting a record takes with it, and the keys that
keep records unique."""

import datetime

import pytest
from sqlalchemy import delete, select
from sqlalchemy.exc import IntegrityError

from backend.store.models import Experiment, Job, ModelPreset, Run, RunJournal, RunTag, Trial, UTCDateTime, utcnow

UTC = datetime.UTC
PLUS_2 = datetime.timezone(datetime.timedelta(hours=2))
NOON_UTC = datetime.datetime(2026, 12, 3, 12, 0, tzinfo=UTC)


def _run(**fields) -> Run:
    columns = {"kind": "sim", "status": "done", "code_version": "test", "model": {"alpha": 77.6},
               "controls": [[30, 0.9]], "start_state": [-0.93, -0.17], "jumps": 4, "alpha": 77.6, "psi0_deg": 30.0,
               "zeta0": 0.9, "jumps_completed": 4, "climb": 1.2, "results": {}}  # fmt: skip
    return Run(**(columns | fields))


def _job(**fields) -> Job:
    return Job(**({"kind": "mjtf", "spec": {}, "state": "queued", "total": 4, "code_version": "test"} | fields))


def _preset(name: str) -> ModelPreset:
    return ModelPreset(name=name, base="paper", physical={}, offsets={}, fit={}, runs=[1], code_version="test")


def test_now_is_timezone_aware_utc():
    assert utcnow().utcoffset() == datetime.timedelta(0)


@pytest.mark.parametrize(
    ("stored", "read"),
    [
        (datetime.datetime(2026, 12, 3, 12, 0), NOON_UTC),  # SQLite's naive text: it was UTC
        (NOON_UTC, NOON_UTC),
        (None, None),
    ],
)
def test_a_timestamp_reads_back_aware_in_utc(stored, read):
    assert UTCDateTime().process_result_value(stored, None) == read


def test_a_timestamp_with_an_offset_is_stored_as_the_same_instant(session):
    """14:00+02:00 is 12:00 UTC: SQLite kept the wall time and dropped the offset, so it read back
    as 14:00 UTC, two hours late."""
    session.add(Experiment(name="abroad", created_at=datetime.datetime(2026, 12, 3, 14, 0, tzinfo=PLUS_2)))
    session.commit()
    session.expunge_all()
    (created,) = session.scalars(select(Experiment.created_at)).all()
    assert created == NOON_UTC and created.tzinfo is not None


def test_a_filter_with_an_offset_compares_instants(session):
    """What ``created_after=…+02:00`` does: an experiment made at noon UTC is after 13:00+02:00
    (11:00 UTC) and before 15:00+02:00 (13:00 UTC)."""
    session.add(Experiment(name="noon", created_at=NOON_UTC))
    session.commit()
    after_11_utc = datetime.datetime(2026, 12, 3, 13, 0, tzinfo=PLUS_2)
    before_13_utc = datetime.datetime(2026, 12, 3, 15, 0, tzinfo=PLUS_2)
    where = (Experiment.created_at >= after_11_utc, Experiment.created_at < before_13_utc)
    assert session.scalars(select(Experiment.name).where(*where)).all() == ["noon"]
    assert session.scalars(select(Experiment.name).where(Experiment.created_at >= before_13_utc)).all() == []


def test_an_experiment_starts_empty_and_timestamped(session):
    experiment = Experiment(name="energy")
    session.add(experiment)
    session.commit()
    assert (experiment.description, experiment.notes, experiment.tags) == ("", "", [])
    assert experiment.created_at.tzinfo is not None and experiment.updated_at.tzinfo is not None


def test_a_runs_tags_are_sorted_and_its_trajectory_flag_follows_the_blob(session):
    run = _run(trajectory=b"path", run_tags=[RunTag(tag="zeta"), RunTag(tag="alpha")])
    plain = _run()
    session.add_all([run, plain])
    session.commit()
    session.expunge_all()
    stored, stored_plain = session.get(Run, run.id), session.get(Run, plain.id)
    assert stored.tags == ["alpha", "zeta"] and stored_plain.tags == []
    assert stored.has_trajectory is True and stored_plain.has_trajectory is False
    assert stored.notes == "" and stored.duration_s == 0.0


def test_deleting_a_run_deletes_its_tags_and_journal(session):
    run = _run(status="running", kind="robot", run_tags=[RunTag(tag="live")])
    session.add(run)
    session.flush()
    session.add(RunJournal(run_id=run.id, data={"frames": []}))
    session.commit()
    session.execute(delete(Run).where(Run.id == run.id))  # the database's own cascade, not the ORM's
    session.commit()
    assert session.scalars(select(RunTag)).all() == [] and session.scalars(select(RunJournal)).all() == []


def test_deleting_a_job_deletes_its_trials(session):
    job = _job(
        trials=[Trial(level=0, index=i, zeta0=0.9, seed=2**32 - 1, jumps=3, failure_code=None) for i in range(2)]
    )
    session.add(job)
    session.commit()
    assert session.get(Trial, job.trials[0].id).seed == 2**32 - 1, "an unsigned 32-bit seed fits"
    session.delete(job)
    session.commit()
    assert session.scalars(select(Trial)).all() == []


@pytest.mark.parametrize("holds", ["run", "job"])
def test_an_experiment_holding_runs_or_jobs_cannot_be_deleted_in_the_database(session, holds):
    experiment = Experiment(name="kept")
    session.add(experiment)
    session.flush()
    session.add(_run(experiment_id=experiment.id) if holds == "run" else _job(experiment_id=experiment.id))
    session.commit()
    with pytest.raises(IntegrityError):
        session.execute(delete(Experiment).where(Experiment.id == experiment.id))
        session.commit()


def test_a_trial_is_stored_once_per_job_level_and_index(session):
    job = _job()
    session.add(job)
    session.flush()
    session.add(Trial(job_id=job.id, level=0, index=0, zeta0=0.9, seed=1, jumps=3, failure_code=None))
    session.commit()
    session.add(Trial(job_id=job.id, level=0, index=0, zeta0=0.9, seed=2, jumps=5, failure_code="slip"))
    with pytest.raises(IntegrityError, match=r"uq_trials_key|UNIQUE"):
        session.commit()


def test_a_preset_name_is_unique(session):
    session.add(_preset("table.v1"))
    session.commit()
    session.add(_preset("table.v1"))
    with pytest.raises(IntegrityError):
        session.commit()
