"""The chunk-map hook: order, progress, cancelling between chunks."""

import pytest

from sim_core.chunks import Cancelled, chunk_slices, in_process


def test_chunk_slices_cover_everything_once():
    parts = chunk_slices(10, 4)
    assert parts == [slice(0, 4), slice(4, 8), slice(8, 10)]
    assert chunk_slices(0, 4) == []
    with pytest.raises(ValueError, match="chunk size"):
        chunk_slices(10, 0)


def test_in_process_keeps_order_and_reports_progress():
    seen = []
    assert in_process(pow, [(2, 1), (2, 2), (2, 3)], lambda done, total: seen.append((done, total))) == [2, 4, 8]
    assert seen == [(1, 3), (2, 3), (3, 3)]


def test_a_progress_callback_cancels_between_chunks():
    ran = []

    def work(x):
        ran.append(x)
        return x

    def cancel_after_two(done, _total):
        if done == 2:
            raise Cancelled

    with pytest.raises(Cancelled):
        in_process(work, [(1,), (2,), (3,), (4,)], cancel_after_two)
    assert ran == [1, 2]
