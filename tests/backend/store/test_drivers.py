"""The database a URL names, checked before the service starts (backend/store/drivers.py): its driver
installed, its server answering, or one line saying what to do."""

from __future__ import annotations

import pytest
from sqlalchemy import make_url
from typer.testing import CliRunner

from backend.store.drivers import StoreUnavailable, check_store, with_driver
from cli.app import app
from tests.helpers import free_port


@pytest.mark.parametrize(
    ("named", "meant"),
    [
        ("postgresql://lab:s3cret@db.example:5433/parkour", "postgresql+psycopg://lab:s3cret@db.example:5433/parkour"),
        ("postgresql+psycopg://lab@db/parkour", "postgresql+psycopg://lab@db/parkour"),
        ("postgresql+pg8000://lab@db/parkour", "postgresql+pg8000://lab@db/parkour"),  # a driver named is kept
        ("sqlite:////tmp/x.sqlite3", "sqlite:////tmp/x.sqlite3"),
    ],
)
def test_postgresql_without_a_driver_means_psycopg(named, meant):
    assert with_driver(named) == meant
    assert make_url(with_driver(named)).password == make_url(named).password  # the password survives


def test_a_missing_driver_names_it_and_what_to_install():
    with pytest.raises(StoreUnavailable) as refused:
        check_store("postgresql+pg8000://lab@127.0.0.1:5432/parkour")
    assert "needs the driver pg8000, which is not installed" in str(refused.value)


def test_a_server_that_does_not_answer_is_named_without_its_password():
    with pytest.raises(StoreUnavailable) as refused:
        check_store(f"postgresql+psycopg://lab:s3cret@127.0.0.1:{free_port()}/parkour")
    message = str(refused.value)
    assert "does not answer" in message and "s3cret" not in message and "\n" not in message


def test_a_url_that_is_no_url_is_named():
    with pytest.raises(StoreUnavailable, match="DATABASE_URL is not a database URL"):
        with_driver("parkour on the lab server")


def test_sqlite_and_an_answering_server_pass(postgres, tmp_path):
    check_store(f"sqlite:///{tmp_path / 'not-created-yet' / 'x.sqlite3'}")  # start-up creates it
    with postgres.fresh() as url:
        check_store(url)


def test_serve_stops_with_one_line_when_the_database_cannot_be_used(monkeypatch, tmp_path):
    monkeypatch.setenv("DATABASE_URL", f"postgresql://lab@127.0.0.1:{free_port()}/parkour")
    result = CliRunner().invoke(app, ["serve", "--data-dir", str(tmp_path), "--no-view"])
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: the database at postgresql+psycopg://lab@127.0.0.1")
