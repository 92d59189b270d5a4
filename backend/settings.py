"""Service settings: where data lives, which database, where to listen, which host names it answers to.

Precedence: command-line options, then environment (``PARKOUR_DATA_DIR``, ``DATABASE_URL``,
``PARKOUR_DASK_ADDRESS``, ``PARKOUR_ALLOWED_HOSTS``), then defaults (``./data`` in a checkout,
SQLite, 127.0.0.1:8000, the loopback names).
"""

from __future__ import annotations

import ipaddress
import os
import re
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

DEFAULT_HOST = "127.0.0.1"  # localhost only unless told otherwise: the robot is real hardware
DEFAULT_PORT = 8000
MAX_REQUEST_BYTES = 1_000_000
# The Host names (and WebSocket Origins) the service answers to unless given more: the loopback's.
LOOPBACK_HOSTS = ("localhost", "127.0.0.1", "::1")
WILDCARD_ADDRESSES = ("", "0.0.0.0", "::", "*")  # interfaces to bind, not names a client uses


def host_name(entry: str) -> str:
    """``entry`` as the allow-list compares it: lower case, no port, IPv6 without brackets
    (``"[::1]:8000"`` → ``"::1"``, ``"Lab-PC:8000"`` → ``"lab-pc"``)."""
    entry = entry.strip().lower()
    if entry.startswith("["):
        return entry[1:].partition("]")[0]
    if entry.count(":") == 1:
        return entry.partition(":")[0]
    return entry  # a name, an IPv4 address, or a bare IPv6 one


@dataclass(frozen=True)
class Settings:
    data_dir: Path
    database_url: str
    dask_address: str | None = None
    max_request_bytes: int = MAX_REQUEST_BYTES
    allowed_hosts: tuple[str, ...] = LOOPBACK_HOSTS  # normalised by host_name
    reads_need_token: bool = False  # True when it listens beyond this machine: every read names who asks

    @classmethod
    def from_environment(
        cls,
        data_dir: Path | None = None,
        database_url: str | None = None,
        allowed_hosts: Iterable[str] = (),
        listen_on: str = DEFAULT_HOST,
    ) -> Settings:
        """``allowed_hosts``: names to answer to beside the loopback's and ``$PARKOUR_ALLOWED_HOSTS``
        (comma- or space-separated); wildcard addresses such as ``0.0.0.0`` are not names and are left out.
        ``listen_on``: the address the service binds; beyond the loopback, reads need a token too."""
        from backend.store.database import sqlite_url  # SQLAlchemy loads here, not when the CLI lists options
        from backend.store.drivers import with_driver

        directory = Path(data_dir or os.environ.get("PARKOUR_DATA_DIR") or Path.cwd() / "data").resolve()
        named_url = database_url or os.environ.get("DATABASE_URL")
        url = with_driver(named_url) if named_url else sqlite_url(directory)
        named = re.split(r"[,\s]+", os.environ.get("PARKOUR_ALLOWED_HOSTS", "")) + list(allowed_hosts)
        hosts = dict.fromkeys(LOOPBACK_HOSTS)
        hosts.update(dict.fromkeys(host_name(entry) for entry in named if host_name(entry) not in WILDCARD_ADDRESSES))
        return cls(
            data_dir=directory,
            database_url=url,
            dask_address=os.environ.get("PARKOUR_DASK_ADDRESS") or None,
            allowed_hosts=tuple(hosts),
            reads_need_token=not is_loopback(listen_on),
        )


def is_loopback(address: str) -> bool:
    """Whether binding ``address`` keeps the service on this machine (``127.0.0.1``, ``::1``,
    ``localhost``); a wildcard (``0.0.0.0``) or a network address does not."""
    if host_name(address) == "localhost":
        return True
    try:
        return ipaddress.ip_address(host_name(address)).is_loopback
    except ValueError:
        return False  # a name other than localhost may resolve anywhere
