"""Service settings (backend/settings.py): options over environment over defaults, the database a
URL names with its driver, and the host names the service answers to, normalised."""

import dataclasses

import pytest

from backend.settings import LOOPBACK_HOSTS, MAX_REQUEST_BYTES, Settings, host_name
from backend.store.database import sqlite_url

ENVIRONMENT = ("PARKOUR_DATA_DIR", "DATABASE_URL", "PARKOUR_DASK_ADDRESS", "PARKOUR_ALLOWED_HOSTS")


@pytest.fixture(autouse=True)
def _bare_environment(monkeypatch, tmp_path):
    """No settings from the environment this test runs in, and ``tmp_path`` as the working directory."""
    for name in ENVIRONMENT:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.chdir(tmp_path)


@pytest.mark.parametrize(
    ("entry", "name"),
    [
        ("localhost", "localhost"),
        (" Lab-PC:8000 ", "lab-pc"),
        ("10.0.0.5:80", "10.0.0.5"),
        ("[::1]:8000", "::1"),
        ("[FE80::1]", "fe80::1"),
        ("fe80::1", "fe80::1"),  # a bare IPv6 address: its colons are not a port
        ("LAB.example", "lab.example"),
    ],
)
def test_a_host_is_compared_lower_case_without_port_or_brackets(entry, name):
    assert host_name(entry) == name


def test_defaults_are_a_sqlite_file_in_data_here_and_the_loopback_names(tmp_path):
    settings = Settings.from_environment()
    assert settings.data_dir == (tmp_path / "data").resolve()
    assert settings.database_url == sqlite_url(settings.data_dir)
    assert (settings.dask_address, settings.max_request_bytes) == (None, MAX_REQUEST_BYTES)
    assert settings.allowed_hosts == LOOPBACK_HOSTS


def test_the_environment_is_read_when_no_option_is_given(monkeypatch, tmp_path):
    monkeypatch.setenv("PARKOUR_DATA_DIR", str(tmp_path / "lab"))
    monkeypatch.setenv("DATABASE_URL", "sqlite:////srv/parkour.sqlite3")
    monkeypatch.setenv("PARKOUR_DASK_ADDRESS", "tcp://scheduler:8786")
    settings = Settings.from_environment()
    assert settings.data_dir == (tmp_path / "lab").resolve()
    assert settings.database_url == "sqlite:////srv/parkour.sqlite3"
    assert settings.dask_address == "tcp://scheduler:8786"


def test_options_win_over_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("PARKOUR_DATA_DIR", str(tmp_path / "lab"))
    monkeypatch.setenv("DATABASE_URL", "sqlite:////srv/parkour.sqlite3")
    settings = Settings.from_environment(tmp_path / "option", "sqlite:////tmp/option.sqlite3")
    assert settings.data_dir == (tmp_path / "option").resolve()
    assert settings.database_url == "sqlite:////tmp/option.sqlite3"


def test_a_data_dir_alone_puts_the_database_in_it(monkeypatch, tmp_path):
    monkeypatch.setenv("PARKOUR_DATA_DIR", str(tmp_path / "lab"))
    assert Settings.from_environment().database_url == sqlite_url((tmp_path / "lab").resolve())


def test_an_empty_dask_address_means_none(monkeypatch):
    monkeypatch.setenv("PARKOUR_DASK_ADDRESS", "")
    assert Settings.from_environment().dask_address is None


def test_settings_apply_the_driver_to_database_url(monkeypatch, tmp_path):
    monkeypatch.setenv("DATABASE_URL", "postgresql://lab@db/parkour")
    assert Settings.from_environment(tmp_path).database_url == "postgresql+psycopg://lab@db/parkour"
    assert Settings.from_environment(tmp_path, "postgresql://x@h/d").database_url == "postgresql+psycopg://x@h/d"


def test_named_hosts_join_the_loopback_names_normalised_once_each(monkeypatch):
    monkeypatch.setenv("PARKOUR_ALLOWED_HOSTS", "lab-pc.example, 10.0.0.5 [fe80::1]:8000,,LAB-PC.example")
    settings = Settings.from_environment(allowed_hosts=["bench", "localhost:8000"])
    assert settings.allowed_hosts == (*LOOPBACK_HOSTS, "lab-pc.example", "10.0.0.5", "fe80::1", "bench")


@pytest.mark.parametrize("wildcard", ["0.0.0.0", "::", "*", "[::]:8000", "0.0.0.0:8000"])
def test_a_wildcard_address_is_not_a_name_to_answer_to(monkeypatch, wildcard):
    monkeypatch.setenv("PARKOUR_ALLOWED_HOSTS", wildcard)
    assert Settings.from_environment(allowed_hosts=[wildcard]).allowed_hosts == LOOPBACK_HOSTS


def test_settings_are_frozen_and_varied_with_replace():
    settings = Settings.from_environment()
    with pytest.raises(dataclasses.FrozenInstanceError):
        settings.max_request_bytes = 1  # type: ignore[misc]
    assert dataclasses.replace(settings, max_request_bytes=5).max_request_bytes == 5
