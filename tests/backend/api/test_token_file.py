"""The API token file (backend/api/token_file.py): written whole or not at all (issue 14).

Before: a first start on a full disk touched ``api_token``, failed to write into it and left it
empty (0 bytes); the next start read the empty file as the token and said nothing, and every
change then answered 401. Now the token goes to a temporary file beside it (mode 600), is fsynced
and renamed over it; a full disk fails the start saying so and leaves nothing; an empty or corrupt
file is replaced by a new token with a warning naming the file.
"""

import errno
import logging
import os
import stat

import pytest

from backend.api.token_file import TOKEN_FILE, api_token
from backend.store import files
from tests.backend.disk import fill, tmpfs


def _mode(path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def _only_the_token_file(directory) -> None:
    assert sorted(path.name for path in directory.iterdir()) == [TOKEN_FILE], "no temporary file is left"


def test_the_token_is_created_once_with_mode_600(tmp_path):
    token, created = api_token(tmp_path)
    assert created and len(token) >= 40
    path = tmp_path / TOKEN_FILE
    assert path.read_text() == token + "\n"
    assert _mode(path) == 0o600
    assert api_token(tmp_path) == (token, False)
    _only_the_token_file(tmp_path)


def test_a_full_disk_fails_the_first_start_and_leaves_no_file(tmp_path, monkeypatch):
    def no_space(_descriptor, _data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files.os, "write", no_space)
    with pytest.raises(OSError, match="is full: cannot store the API token") as raised:
        api_token(tmp_path)
    assert raised.value.errno == errno.ENOSPC
    assert list(tmp_path.iterdir()) == [], "neither an empty api_token nor a temporary file"
    monkeypatch.undo()  # space again: the next start makes a whole token
    token, created = api_token(tmp_path)
    assert created and (tmp_path / TOKEN_FILE).read_text() == token + "\n"


def test_a_crash_before_the_rename_keeps_the_old_token(tmp_path, monkeypatch):
    """The old file stays until the new one is whole: replacing is a rename, never a rewrite in place."""
    (tmp_path / TOKEN_FILE).write_text("")  # to be replaced...
    monkeypatch.setattr(files.os, "replace", lambda *_: (_ for _ in ()).throw(OSError(errno.EIO, "I/O error")))
    with pytest.raises(OSError, match="I/O error"):
        api_token(tmp_path)
    assert (tmp_path / TOKEN_FILE).read_text() == "", "...but only by a whole new file"
    _only_the_token_file(tmp_path)


@pytest.mark.parametrize(
    ("content", "problem"),
    [
        (b"", "empty"),
        (b"\n  \n", "empty"),
        (b"\0" * 44, "corrupt"),  # what a crash can leave on some filesystems
        (b"\xff\xfe garbage", "corrupt"),
        (b"abc\n", "corrupt"),
        (b"two tokens-are-not-one-token\n", "corrupt"),
    ],
    ids=["empty", "blank-lines", "nul-bytes", "not-text", "too-short", "two-words"],
)
def test_an_empty_or_corrupt_token_file_is_replaced_loudly(tmp_path, caplog, content, problem):
    path = tmp_path / TOKEN_FILE
    path.write_bytes(content)
    with caplog.at_level(logging.WARNING, logger="parkourlab.api"):
        token, created = api_token(tmp_path)
    assert created, "a replaced token is a new one: `parkour serve` prints it"
    assert path.read_text() == token + "\n" and _mode(path) == 0o600
    warning = [record.getMessage() for record in caplog.records if record.levelno == logging.WARNING]
    assert len(warning) == 1 and str(path) in warning[0] and problem in warning[0], warning
    assert api_token(tmp_path) == (token, False)


def test_a_token_set_by_hand_is_kept(tmp_path):
    (tmp_path / TOKEN_FILE).write_text("  lab-wall-2026-token  \n")
    assert api_token(tmp_path) == ("lab-wall-2026-token", False)


def test_a_first_start_on_a_really_full_disk(tmp_path):
    """A real full filesystem (a small tmpfs; root only): the start fails with ENOSPC and no file;
    with space again the next start creates a whole token."""
    with tmpfs(tmp_path / "disk", "1m") as disk:
        ballast = fill(disk)
        with pytest.raises(OSError, match="is full") as raised:
            api_token(disk)
        assert raised.value.errno == errno.ENOSPC
        assert sorted(os.listdir(disk)) == [ballast.name], "no empty api_token (it used to be 0 bytes)"
        ballast.unlink()
        token, created = api_token(disk)
        assert created and (disk / TOKEN_FILE).read_text() == token + "\n"
