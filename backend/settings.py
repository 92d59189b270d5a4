"""Service settings: where data lives, which database, where to listen.

Precedence: command-line options, then environment (``PARKOUR_DATA_DIR``, ``DATABASE_URL``,
``PARKOUR_DASK_ADDRESS``), then defaults (``./data`` in a checkout, SQLite, 127.0.0.1:8000).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

DEFAULT_HOST = "127.0.0.1"  # localhost only unless told otherwise: the robot is real hardware
DEFAULT_PORT = 8000
MAX_REQUEST_BYTES = 1_000_000


@dataclass(frozen=True)
class Settings:
    data_dir: Path
    database_url: str
    dask_address: str | None = None
    max_request_bytes: int = MAX_REQUEST_BYTES

    @classmethod
    def from_environment(cls, data_dir: Path | None = None, database_url: str | None = None) -> Settings:
        from backend.store.database import sqlite_url  # SQLAlchemy loads here, not when the CLI lists options

        directory = Path(data_dir or os.environ.get("PARKOUR_DATA_DIR") or Path.cwd() / "data").resolve()
        url = database_url or os.environ.get("DATABASE_URL") or sqlite_url(directory)
        return cls(data_dir=directory, database_url=url, dask_address=os.environ.get("PARKOUR_DASK_ADDRESS") or None)
