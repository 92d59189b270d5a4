"""What every repository shares (backend/repositories/common.py): one row by id or NotFound naming
it, one row locked and read fresh for a change, and keyset pages newest first."""

import pytest
from sqlalchemy import update

from backend.errors import NotFound
from backend.repositories.common import fetch, locked, newest_first, page
from backend.store.models import Experiment


@pytest.fixture
def five(sessions) -> list[int]:
    """Five experiments' ids, oldest first."""
    with sessions() as session:
        experiments = [Experiment(name=f"e{i}") for i in range(5)]
        session.add_all(experiments)
        session.commit()
        return [experiment.id for experiment in experiments]


def test_fetch_finds_a_row_or_names_what_is_missing(session, five):
    assert fetch(session, Experiment, five[2], "experiment").name == "e2"
    with pytest.raises(NotFound, match=r"^experiment 999 does not exist$"):
        fetch(session, Experiment, 999, "experiment")


def test_locked_takes_the_write_lock_before_it_reads(sessions, five):
    with sessions() as session:
        assert locked(session, Experiment, five[0], "experiment").name == "e0"
        assert session.connection().connection.dbapi_connection.in_transaction, "BEGIN IMMEDIATE: held to commit"


def test_locked_reads_the_row_fresh_not_the_sessions_older_copy(sessions, five):
    with sessions() as editor:
        stale = editor.get(Experiment, five[0])
        assert stale.name == "e0"
        editor.commit()  # the session keeps its copy (expire_on_commit off)
        with sessions() as other:
            other.execute(update(Experiment).where(Experiment.id == five[0]).values(name="renamed"))
            other.commit()
        assert editor.get(Experiment, five[0]).name == "e0", "the stale copy, as a plain read sees it"
        assert locked(editor, Experiment, five[0], "experiment").name == "renamed"
        with pytest.raises(NotFound, match="experiment 999"):
            locked(editor, Experiment, 999, "experiment")


@pytest.mark.parametrize("limit", [1, 2, 3, 5, 6])
def test_keyset_pages_list_every_row_once_newest_first(session, five, limit):
    pages, cursor = [], None
    while True:
        rows, cursor = page(list(session.scalars(newest_first(Experiment, limit, cursor))), limit)
        pages.append([row.id for row in rows])
        if cursor is None:
            break
        assert cursor == rows[-1].id, "the next page starts after the last row shown"
    assert [row_id for chunk in pages for row_id in chunk] == five[::-1]
    assert all(len(chunk) == limit for chunk in pages[:-1]) and 0 < len(pages[-1]) <= limit
    assert len(pages) == -(-len(five) // limit), "no empty page at the end when the rows fill the last one"


def test_a_page_asks_for_one_row_more_than_it_shows():
    """The extra row says whether there is a next page; it is not shown."""

    class Row:
        def __init__(self, identifier: int):
            self.id = identifier

    rows = [Row(9), Row(7), Row(4)]
    shown, cursor = page(rows, 2)
    assert [row.id for row in shown] == [9, 7] and cursor == 7
    assert page(rows, 3) == (rows, None)
    assert page([], 3) == ([], None)


def test_a_cursor_past_the_oldest_row_is_an_empty_last_page(session, five):
    rows = list(session.scalars(newest_first(Experiment, 10, five[0])))
    assert page(rows, 10) == ([], None)
