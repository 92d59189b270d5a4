"""Calibrations' bodies (backend/schemas/calibrations.py): the runs to fit and the preset's name
asked for, and the fitted preset and touchdown comparison read back (null where not identifiable)."""

import datetime
import re

import pytest

from backend.schemas.calibrations import PRESET_PATTERN, CalibrationCreate, CalibrationOut, TouchdownComparison
from backend.schemas.common import MAX_ID, ModelIn
from tests.backend.schemas.refusals import accepted, refused

NAMES = ["table.v1", "lab-2026_12", "A", "x" * 64, "", "-x", ".x", "a b", "x/y", "x" * 65, "ünï"]


def test_a_calibration_fits_1_to_100_stored_runs():
    assert accepted(CalibrationCreate, {"runs": [1], "name": "x"}).runs == [1]
    assert len(accepted(CalibrationCreate, {"runs": list(range(1, 101)), "name": "x"}).runs) == 100
    assert refused(CalibrationCreate, {"runs": [], "name": "x"}) == [("runs",)]
    assert refused(CalibrationCreate, {"runs": list(range(1, 102)), "name": "x"}) == [("runs",)]


def test_each_run_is_a_record_id():
    assert accepted(CalibrationCreate, {"runs": [MAX_ID], "name": "x"}).runs == [MAX_ID]
    assert refused(CalibrationCreate, {"runs": [1, 0], "name": "x"}) == [("runs", 1)]
    assert refused(CalibrationCreate, {"runs": [MAX_ID + 1], "name": "x"}) == [("runs", 0)]


@pytest.mark.parametrize("name", NAMES)
def test_a_name_a_calibration_may_store_is_one_a_model_may_ask_for(name):
    """The preset's name is the same pattern here and in ``ModelIn.preset``: no calibration can be
    stored under a name no request could use."""
    stores = re.fullmatch(PRESET_PATTERN, name) is not None
    if stores:
        assert accepted(CalibrationCreate, {"runs": [1], "name": name}).name == name
        assert accepted(ModelIn, {"preset": name}).preset == name
    else:
        assert refused(CalibrationCreate, {"runs": [1], "name": name}) == [("name",)]
        assert refused(ModelIn, {"preset": name}) == [("preset",)]


def test_a_fit_starts_from_the_paper_preset_only():
    assert accepted(CalibrationCreate, {"runs": [1], "name": "x"}).preset == "paper"
    assert refused(CalibrationCreate, {"runs": [1], "name": "x", "preset": "table.v1"}) == [("preset",)]


def test_a_request_needs_runs_and_a_name_and_nothing_else():
    assert refused(CalibrationCreate, {"name": "x"}) == [("runs",)]
    assert refused(CalibrationCreate, {"runs": [1]}) == [("name",)]
    assert refused(CalibrationCreate, {"runs": [1], "name": "x", "alpha": 70.0}) == [("alpha",)]


FIT = {
    "params": {"alpha": 72.0, "c_zeta": 1.2, "c_psi": 0.8, "psi0_offset_deg": [0.6, -0.8], "zeta0_offset": [0.0, 0.0]},
    "stderr": {"alpha": 1.5, "c_zeta": None, "c_psi": None, "psi0_offset_deg": [0.1, None], "zeta0_offset": [None] * 2},
    "parameters": ["alpha", "c_zeta"],
    "correlation": [[1.0, None], [None, 1.0]],
    "unidentifiable": ["c_psi"],
    "confounded": [("alpha", "c_zeta", 0.97)],
    "touchdowns_used": 40,
    "rms_residual_before": 0.05,
    "rms_residual_after": None,
    "residuals": {"xdot": {"unit": "sqrt(g l0)", "rms_before": 0.04, "rms_after": None}},
    "noise": {"xdot": 0.01, "rise": None},
    "failed_predictions": 0,
    "preset": {
        "name": "table.v1",
        "base": "paper",
        "runs": [1, 2],
        "created_at": datetime.datetime(2026, 12, 1, tzinfo=datetime.UTC),
        "code_version": "abc123",
        "physical": {"mass": 1.54, "mu": None},
    },
}


def test_a_fitted_preset_reads_back_with_nulls_where_not_identifiable():
    out = CalibrationOut.model_validate(FIT)
    assert out.stderr.c_zeta is None and out.stderr.psi0_offset_deg == [0.1, None]
    assert out.confounded == [("alpha", "c_zeta", 0.97)]
    assert CalibrationOut.model_validate_json(out.model_dump_json()) == out


@pytest.mark.parametrize("pair", [[0.6], [0.6, -0.8, 0.0]])
def test_a_left_right_offset_is_exactly_two_numbers(pair):
    params = FIT["params"] | {"psi0_offset_deg": pair}
    assert refused(CalibrationOut, FIT | {"params": params}) == [("params", "psi0_offset_deg")]


def test_a_touchdown_comparison_without_a_calibration_has_no_calibrated_channels():
    channels = {"xdot": -0.9, "ydot": None, "rise": 0.3}
    comparison = TouchdownComparison.model_validate(
        {
            "run_id": 4,
            "base": "paper",
            "preset": None,
            "touchdowns": [
                {"index": 0, "time": 1.5, "wall": "left", "measured": channels, "paper": channels,
                 "paper_residual": channels},
            ],
            "rms": {"paper": channels},
        }
    )  # fmt: skip
    (touchdown,) = comparison.touchdowns
    assert touchdown.calibrated is None and touchdown.calibrated_residual is None
    assert touchdown.measured.ydot is None
    assert TouchdownComparison.model_validate_json(comparison.model_dump_json()) == comparison
