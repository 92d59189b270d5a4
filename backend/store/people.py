"""The lab's people and their tokens: ``people.json`` in the data directory (mode 600).

Each person has a name, an access (``write``: may change what the service keeps; ``read``: may
only read) and a bearer token, of which only its SHA-256 is kept: the file names who may do what,
and a copy of it signs nobody in. ``parkour token add NAME`` makes a token and prints it once;
``parkour token revoke NAME`` removes it. Both work while the service runs: the service looks the
file up again whenever it changed (a ``stat`` per request), so a revoked token is refused at once.

The service's own token (``api_token``, :mod:`backend.api.token_file`) is the lab's: it signs in as
:data:`LAB`, with write access, so the scripts and links made before people had names go on working.

Changes take a lock (``people.json.lock``, ``flock``) around read-modify-write, and the file is
written whole or not at all: two ``parkour token add`` at once both land, and a crash or a full
disk leaves the old file or the new one.
"""

from __future__ import annotations

import contextlib
import datetime
import fcntl
import hashlib
import json
import re
import secrets
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

from backend.store.files import write_atomically

PEOPLE_FILE = "people.json"
LAB = "lab"  # who the service's own token (api_token) signs in as
NAME_PATTERN = r"[A-Za-z][A-Za-z0-9._-]{0,31}"  # what a person's name may be: it is shown beside what they did
NAME_RULE = "1 to 32 characters: a letter, then letters, digits, '.', '_' or '-'"
_NAME = re.compile(NAME_PATTERN)


class Access(StrEnum):
    """What a person's token may do: ``write`` everything a token allows, ``read`` only read."""

    WRITE = "write"
    READ = "read"


@dataclass(frozen=True)
class Person:
    """Who a request comes from: ``name`` and what their token may do."""

    name: str
    access: Access = Access.WRITE

    @property
    def may_change(self) -> bool:
        return self.access is Access.WRITE


@dataclass(frozen=True)
class PersonEntry:
    """A person as the file keeps them: the token's SHA-256 (hex), never the token."""

    name: str
    access: Access
    token_sha256: str
    created_at: str  # ISO 8601, UTC

    def as_json(self) -> dict:
        return {"name": self.name, "access": self.access.value, "token_sha256": self.token_sha256,
                "created_at": self.created_at}  # fmt: skip


class PeopleError(ValueError):
    """A change to the people file that cannot be made (a name taken, unknown or not allowed)."""


def check_name(name: str) -> str:
    """``name`` if it may name a person, else :class:`PeopleError` saying what a name may be."""
    if not _NAME.fullmatch(name):
        raise PeopleError(f"name {name!r} is not allowed: {NAME_RULE}")
    if name == LAB:
        raise PeopleError(f"name {LAB!r} is taken by the service's own token (api_token): choose another")
    return name


def token_digest(token: str) -> str:
    return hashlib.sha256(token.encode("utf-8", "replace")).hexdigest()


class PeopleFile:
    """The people file of one data directory: changes (:meth:`add`, :meth:`revoke`) and the
    service's look-up (:meth:`who`), which reads the file again only when it changed."""

    def __init__(self, data_dir: Path):
        self.path = Path(data_dir) / PEOPLE_FILE
        self._lock = threading.Lock()  # the service's threads share the cached look-up table
        self._seen: tuple | None = None  # the file's (inode, size, mtime) when last read
        self._by_digest: dict[str, Person] = {}

    # Changes (the CLI) ----------------------------------------------------------------------------
    def add(self, name: str, access: Access = Access.WRITE) -> str:
        """Give ``name`` a new token with ``access``; the token, which is not kept (only its hash)."""
        check_name(name)
        token = secrets.token_urlsafe(32)
        with self._changing() as people:
            if any(entry.name == name for entry in people):
                raise PeopleError(f"{name} has a token already: revoke it first (parkour token revoke {name})")
            now = datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds")
            people.append(PersonEntry(name, Access(access), token_digest(token), now))
        return token

    def revoke(self, name: str) -> None:
        """Remove ``name``'s token: the service refuses it from its next request on."""
        with self._changing() as people:
            kept = [entry for entry in people if entry.name != name]
            if len(kept) == len(people):
                raise PeopleError(f"nobody named {name!r} has a token (parkour token list shows who has)")
            people[:] = kept

    def entries(self) -> list[PersonEntry]:
        """Everyone with a token, in the order they were added."""
        return _parse(self.path)

    @contextlib.contextmanager
    def _changing(self) -> Iterator[list[PersonEntry]]:
        """The people as a list to change in place, under the file's lock; written back whole."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with open(self.path.with_name(PEOPLE_FILE + ".lock"), "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            people = _parse(self.path)
            yield people
            document = {"version": 1, "people": [entry.as_json() for entry in people]}
            write_atomically(self.path, (json.dumps(document, indent=1) + "\n").encode())

    # The service's look-up ------------------------------------------------------------------------
    def who(self, token: str) -> Person | None:
        """The person ``token`` belongs to, or None: as the file says now."""
        digest = token_digest(token)
        with self._lock:
            self._refresh()
            return self._by_digest.get(digest)

    def _refresh(self) -> None:
        try:
            status = self.path.stat()
            seen = (status.st_ino, status.st_size, status.st_mtime_ns)
        except FileNotFoundError:
            seen = None
        if seen == self._seen:
            return
        try:
            people = _parse(self.path)
        except PeopleError:
            people = []  # a file that cannot be read signs nobody in (the lab's token still works)
        self._by_digest = {entry.token_sha256: Person(entry.name, entry.access) for entry in people}
        self._seen = seen


def _parse(path: Path) -> list[PersonEntry]:
    """The file's people ([] if there is no file); :class:`PeopleError` if it cannot be read."""
    try:
        document = json.loads(path.read_text())
    except FileNotFoundError:
        return []
    except (OSError, ValueError) as error:
        raise PeopleError(f"the people file {path} cannot be read: {error}") from error
    try:
        return [
            PersonEntry(str(item["name"]), Access(item["access"]), str(item["token_sha256"]), str(item["created_at"]))
            for item in document["people"]
        ]
    except (KeyError, TypeError, ValueError) as error:
        raise PeopleError(f"the people file {path} is not as written by parkour token: {error}") from error
