"""The database a URL names, checked before the service starts: its driver installed, the server
answering — or one line saying what to do.

``DATABASE_URL=postgresql://…`` means psycopg 3 here (the driver the ``postgres`` extra installs,
and ``./run.sh`` installs when ``DATABASE_URL`` names PostgreSQL), where SQLAlchemy alone would
look for psycopg2.
"""

from __future__ import annotations

from sqlalchemy import make_url
from sqlalchemy.exc import ArgumentError, DBAPIError

DEFAULT_DRIVERS = {"postgresql": "postgresql+psycopg"}
# The drivers this project installs, by module: how to get one that is missing.
INSTALL_HINTS = {
    "psycopg": "install the PostgreSQL extra: .venv/bin/pip install -e '.[postgres]'"
    " (./run.sh does when DATABASE_URL names PostgreSQL)",
}


class StoreUnavailable(RuntimeError):
    """The database cannot be used; the message says why and what to do, in one line."""


def with_driver(url: str) -> str:
    """``url`` with the driver this project installs for its database, where it names none."""
    try:
        parsed = make_url(url)
    except ArgumentError as error:
        message = f"DATABASE_URL is not a database URL ({error}); e.g. postgresql://user@host/db"
        raise StoreUnavailable(message) from None
    driver = DEFAULT_DRIVERS.get(parsed.drivername)
    return url if driver is None else parsed.set(drivername=driver).render_as_string(hide_password=False)


def check_store(url: str) -> None:
    """Connect to the server ``url`` names once (a SQLite file needs no check: start-up creates it).

    Raises:
        StoreUnavailable: the driver is not installed, or the server does not answer.
    """
    from backend.store.database import make_engine

    parsed = make_url(url)
    if parsed.get_backend_name() == "sqlite":
        return
    shown = parsed.render_as_string(hide_password=True)
    try:
        engine = make_engine(url)
    except ModuleNotFoundError as missing:
        hint = INSTALL_HINTS.get(missing.name, f"install the Python package {missing.name}")
        raise StoreUnavailable(f"{shown} needs the driver {missing.name}, which is not installed: {hint}") from None
    try:
        with engine.connect():
            pass
    except DBAPIError as error:
        reason = str(error.orig).strip().splitlines()[0] if error.orig is not None else type(error).__name__
        raise StoreUnavailable(f"the database at {shown} does not answer: {reason}") from None
    finally:
        engine.dispose()
