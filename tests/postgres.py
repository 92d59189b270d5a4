"""A scratch PostgreSQL server for the tests, and a fresh database per test on it.

The store and API tests run against SQLite and, where a server can be had, PostgreSQL (issue 14).
The server is ``$PARKOUR_TEST_POSTGRES_URL`` when that names one (its role needs CREATEDB), or else
one this module starts from Debian's ``postgresql`` binaries (``./test.sh`` installs them when it
can, as it does Chromium): a throwaway cluster in a temporary directory, listening on a free port
of 127.0.0.1, stopped at the end of the session. Durability is off there (``fsync``, full page
writes): nothing in it outlives the tests.

Each test gets its own database, copied from a template the service's migrations were applied to
once (``CREATE DATABASE … TEMPLATE``, tens of milliseconds), and dropped after it.
"""

from __future__ import annotations

import contextlib
import glob
import itertools
import os
import pwd
import shutil
import subprocess
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from tests.helpers import free_port

TEMPLATE = "parkour_template"
START_TIMEOUT = 30.0  # [s]
_NUMBERS = itertools.count()


def server_binaries() -> Path | None:
    """The newest installed PostgreSQL's ``bin`` directory (Debian keeps them off PATH), or None."""
    found = sorted(glob.glob("/usr/lib/postgresql/*/bin/initdb"), key=lambda path: int(Path(path).parts[-3]))
    if found:
        return Path(found[-1]).parent
    initdb = shutil.which("initdb")
    return Path(initdb).parent if initdb else None


def why_unavailable() -> str | None:
    """Why no PostgreSQL can be had for the tests, or None when one can."""
    if os.environ.get("PARKOUR_TEST_POSTGRES_URL"):
        return None
    try:
        import psycopg  # noqa: F401  (the driver the service's URL names)
    except ImportError:
        return "psycopg is not installed (pip install -e '.[postgres]')"
    if server_binaries() is None:
        return "no PostgreSQL server: install Debian's postgresql, or set PARKOUR_TEST_POSTGRES_URL"
    if os.geteuid() == 0:
        try:
            pwd.getpwnam("postgres")
        except KeyError:
            return "running as root with no 'postgres' user to run the server as"
    return None


class ScratchServer:
    """A PostgreSQL cluster in a temporary directory, started by :meth:`start`, removed by :meth:`stop`.

    PostgreSQL refuses to run as root; as root the cluster belongs to Debian's ``postgres`` user."""

    def __init__(self) -> None:
        self.bin = server_binaries()
        self.port = free_port()
        self.directory = Path(tempfile.mkdtemp(prefix="parkour-postgres-"))
        self.data = self.directory / "data"
        self._as_postgres = os.geteuid() == 0
        self.user = "postgres"

    def _run(self, *command: str) -> subprocess.CompletedProcess:
        prefix = ["runuser", "-u", "postgres", "--"] if self._as_postgres else []
        return subprocess.run(
            [*prefix, *command], capture_output=True, text=True, check=True, timeout=START_TIMEOUT, cwd=self.directory
        )

    def start(self) -> str:
        """Start the server; its admin URL (database ``postgres``)."""
        if self._as_postgres:
            shutil.chown(self.directory, "postgres")
        data = str(self.data)
        self._run(str(self.bin / "initdb"), "-D", data, "-U", self.user, "-A", "trust", "-E", "UTF8", "--no-sync")
        options = f"-c listen_addresses=127.0.0.1 -c port={self.port} -c unix_socket_directories={self.directory}"
        options += " -c fsync=off -c full_page_writes=off -c synchronous_commit=off -c max_connections=200"
        log = str(self.directory / "log")
        self._run(str(self.bin / "pg_ctl"), "-D", data, "-o", options, "-l", log, "-w", "start")
        return f"postgresql+psycopg://{self.user}@127.0.0.1:{self.port}/postgres"

    def stop(self) -> None:
        # Never started, or already gone: the directory goes either way.
        with contextlib.suppress(subprocess.CalledProcessError, subprocess.TimeoutExpired):
            self._run(str(self.bin / "pg_ctl"), "-D", str(self.data), "-m", "immediate", "stop")
        shutil.rmtree(self.directory, ignore_errors=True)


def _database_url(admin_url: str, name: str) -> str:
    from sqlalchemy import make_url

    return make_url(admin_url).set(database=name).render_as_string(hide_password=False)


class Databases:
    """Fresh databases on one server, each a copy of a migrated template."""

    def __init__(self, admin_url: str):
        from sqlalchemy import create_engine
        from sqlalchemy.pool import NullPool

        self.admin_url = admin_url
        # CREATE/DROP DATABASE cannot run in a transaction: autocommit.
        self._admin = create_engine(admin_url, isolation_level="AUTOCOMMIT", poolclass=NullPool)
        self._prefix = f"parkour_test_{os.getpid()}_"
        self._create_template()

    def _execute(self, statement: str) -> None:
        from sqlalchemy import text

        with self._admin.connect() as connection:
            connection.execute(text(statement))

    def _create_template(self) -> None:
        from backend.store.database import make_engine, migrate

        self.template = f"{self._prefix}{TEMPLATE}"
        self._execute(f'DROP DATABASE IF EXISTS "{self.template}" WITH (FORCE)')
        self._execute(f'CREATE DATABASE "{self.template}"')
        engine = make_engine(_database_url(self.admin_url, self.template))
        try:
            migrate(engine)
        finally:
            engine.dispose()

    @contextmanager
    def fresh(self, *, migrated: bool = True) -> Iterator[str]:
        """A new database, as a URL: at the schema's head, or empty (``migrated=False``, for the
        migrations' own tests); dropped afterwards, its connections closed."""
        name = f"{self._prefix}{next(_NUMBERS)}"
        self._execute(f'CREATE DATABASE "{name}" TEMPLATE "{self.template if migrated else "template0"}"')
        try:
            yield _database_url(self.admin_url, name)
        finally:
            self._execute(f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')

    def close(self) -> None:
        self._execute(f'DROP DATABASE IF EXISTS "{self.template}" WITH (FORCE)')
        self._admin.dispose()


@contextmanager
def postgres_databases() -> Iterator[Databases]:
    """The session's :class:`Databases`: on ``$PARKOUR_TEST_POSTGRES_URL``, or on a scratch server."""
    url = os.environ.get("PARKOUR_TEST_POSTGRES_URL")
    server = None
    if not url:
        server = ScratchServer()
        try:
            url = server.start()
        except (subprocess.CalledProcessError, subprocess.TimeoutExpired) as error:
            server.stop()
            details = getattr(error, "stderr", "") or ""
            raise RuntimeError(f"could not start a scratch PostgreSQL server: {details.strip()[-500:]}") from error
    deadline = time.monotonic() + START_TIMEOUT
    while True:
        try:
            databases = Databases(url)
            break
        except Exception:
            if time.monotonic() > deadline:
                if server:
                    server.stop()
                raise
            time.sleep(0.2)
    try:
        yield databases
    finally:
        databases.close()
        if server:
            server.stop()
