"""Issue 27's virtual-robot check at a reduced size (scripts/virtual_robot_study.py is the full
figure): on robots whose physics and servo offsets are unlike the paper's, the LQR designed on a
calibration from four open-loop runs holds the height where the paper-model LQR and the PID do
measurably worse. The truth only simulates the robot; the laws see the calibration or the paper."""

import pytest

from scripts.virtual_robot_study import study

CONTROLLERS = (("pid", "paper"), ("lqr", "paper"), ("lqr", "calibrated"))


@pytest.mark.parametrize("truth", ["soft", "finding"])
def test_the_calibrated_lqr_holds_where_the_paper_laws_do_worse(truth):
    result = study(truth, CONTROLLERS, runs_per=3, jumps=150, target_m=0.55)
    pid, paper_lqr, calibrated = result["controllers"]
    assert calibrated["held"] == 3 and calibrated["fell"] == 0, calibrated
    assert calibrated["mean_abs_error_m_when_held"] < 0.012, calibrated
    for worse in (pid, paper_lqr):
        assert worse["held"] < calibrated["held"], worse
        errors = [o["mean_abs_error_m"] for o in worse["outcomes"] if o["mean_abs_error_m"] is not None]
        assert not errors or max(errors) > 2 * calibrated["mean_abs_error_m_when_held"], worse
