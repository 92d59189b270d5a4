"""The API token's file: created once in the data directory (``api_token``, mode 600), written whole
or not at all, and replaced, loudly, when it is empty or corrupt.

Mutating calls carry ``Authorization: Bearer <token>``; :mod:`backend.api.security` checks it on
every request. This module only keeps it: :func:`api_token` reads it, or makes it at the first start.
"""

from __future__ import annotations

import errno
import logging
import secrets
from pathlib import Path

from backend.store.files import write_atomically

TOKEN_FILE = "api_token"
MIN_TOKEN_LENGTH = 16  # token_urlsafe(32) makes 43 characters; a token set by hand may be shorter, not this short

log = logging.getLogger("parkourlab.api")


def api_token(data_dir: Path) -> tuple[str, bool]:
    """The bearer token for mutating calls: ``(token, created_now)``; created once, kept in the data dir.

    The file is written whole or not at all (:func:`write_atomically`): a first start on a full
    disk fails, saying so, and leaves no file — it used to leave an empty one, which the next start
    took as the token (every change then answered 401). An empty or corrupt file is replaced by a
    new token, with a warning naming it (``created_now`` is then true: ``parkour serve`` prints it)."""
    path = Path(data_dir) / TOKEN_FILE
    if path.exists():
        token, problem = _read_token(path)
        if token is not None:
            return token, False
        log.warning("the API token file %s is %s: replacing it with a new token (clients need it)", path, problem)
    path.parent.mkdir(parents=True, exist_ok=True)
    token = secrets.token_urlsafe(32)
    try:
        write_atomically(path, (token + "\n").encode())
    except OSError as error:
        if error.errno in (errno.ENOSPC, errno.EDQUOT):
            raise OSError(error.errno, f"the disk holding {path.parent} is full: cannot store the API token") from error
        raise
    return token, True


def _read_token(path: Path) -> tuple[str | None, str]:
    """The token in ``path``, or None and what is wrong with the file."""
    try:
        token = path.read_bytes().decode("ascii").strip()
    except UnicodeDecodeError:
        return None, "corrupt (not text)"
    if not token:
        return None, "empty"
    if len(token) < MIN_TOKEN_LENGTH or not token.isprintable() or any(char.isspace() for char in token):
        return None, f"corrupt (not one token of {MIN_TOKEN_LENGTH} or more printable characters)"
    return token, ""
