"""The 3D view's bodies (backend/schemas/view.py): which panel's view, which stored runs to replay."""

import re

import pytest

from backend.schemas.common import MAX_ID
from backend.schemas.view import VIEWER_ID_PATTERN, ViewOut, ViewReplay
from tests.backend.schemas.refusals import accepted, refused

VIEWER = "panel_01-ab"


@pytest.mark.parametrize("viewer", ["a" * 8, "A" * 64, "Zz09_-__", VIEWER])
def test_a_viewer_id_is_8_to_64_letters_digits_dashes_or_underscores(viewer):
    assert accepted(ViewReplay, {"viewer": viewer, "run_id": 1}).viewer == viewer
    assert re.fullmatch(VIEWER_ID_PATTERN, viewer)


@pytest.mark.parametrize("viewer", ["a" * 7, "a" * 65, "panel 001", "panel/001", "../../etc", "panel.001", ""])
def test_a_viewer_id_outside_the_pattern_is_refused(viewer):
    assert refused(ViewReplay, {"viewer": viewer, "run_id": 1}) == [("viewer",)]


@pytest.mark.parametrize("field", ["run_id", "overlay_run_id"])
def test_the_runs_replayed_are_record_ids(field):
    body = {"viewer": VIEWER, "run_id": 1}
    assert getattr(accepted(ViewReplay, body | {field: MAX_ID}), field) == MAX_ID
    assert refused(ViewReplay, body | {field: 0}) == [(field,)]
    assert refused(ViewReplay, body | {field: MAX_ID + 1}) == [(field,)]


def test_a_replay_needs_a_viewer_and_a_run_and_nothing_else():
    assert accepted(ViewReplay, {"viewer": VIEWER, "run_id": 3}).overlay_run_id is None, "no ghost unless asked"
    assert refused(ViewReplay, {"run_id": 3}) == [("viewer",)]
    assert refused(ViewReplay, {"viewer": VIEWER}) == [("run_id",)]
    assert refused(ViewReplay, {"viewer": VIEWER, "run_id": 3, "mode": "live"}) == [("mode",)]


def test_a_view_that_is_not_there_says_only_that_and_why():
    absent = ViewOut(available=False, reason="the 3D view is not installed")
    assert absent.model_dump() == {
        "available": False,
        "port": None,
        "mode": None,
        "run_id": None,
        "updates_per_s": None,
        "clients": None,
        "reason": "the 3D view is not installed",
        "starting": False,
    }
    shown = ViewOut(available=True, port=8080, mode="replay", run_id=4, updates_per_s=30.0, clients=1)
    assert ViewOut.model_validate_json(shown.model_dump_json()) == shown
