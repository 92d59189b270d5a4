"""What a calibration fits and reports (sim_core.calibration.fit): the seven-number vector packs and
unpacks a model and its leg offsets exactly, and a fit's ``to_dict`` is the ``parkour calibrate
--json`` contract."""

import json
import math

import numpy as np

from sim_core.calibration.fit import PARAMETERS, CalibrationFit, Outlier, split, vector_of
from sim_core.model.controls import LegOffsets
from sim_core.model.params import ModelParams

BASE = ModelParams(alpha=60.0, d_hat=1.2, c_zeta=0.3, c_psi=0.2, mu=0.9)
OFFSETS = LegOffsets(psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))


def test_the_vector_round_trips_and_keeps_the_base_models_other_parameters():
    vector = np.array([72.0, 1.25, 0.8, 0.6, -0.8, 0.004, -0.005])
    model, offsets = split(BASE, vector)
    assert (model.alpha, model.c_zeta, model.c_psi) == (72.0, 1.25, 0.8)
    assert (model.d_hat, model.mu) == (BASE.d_hat, BASE.mu), "d_hat and mu are not fitted"
    assert offsets == OFFSETS
    assert vector_of(model, offsets).tolist() == vector.tolist()
    assert len(vector) == len(PARAMETERS)


def a_fit() -> CalibrationFit:
    stderr = dict(zip(PARAMETERS, [0.5, 0.04, 0.02, 0.09, 0.08, math.inf, 0.0008], strict=True))
    correlation = np.eye(len(PARAMETERS))
    correlation[5, :] = correlation[:, 5] = np.nan
    return CalibrationFit(
        model=BASE,
        offsets=OFFSETS,
        stderr=stderr,
        correlation=correlation,
        unidentifiable=("zeta0_offset.left",),
        confounded=(("alpha", "c_zeta", 0.97),),
        touchdowns_used=200,
        rms_before=0.17,
        rms_after=0.025,
        channels={"xdot": {"unit": "sqrt(g l0)", "rms_before": 0.2, "rms_after": 0.03}},
        noise={"psi0_deg": 0.5},
        failed_predictions=1,
        outliers=(Outlier(series=2, touchdown=40, residual=math.inf),),
        cut_at_fall=((2, 41),),
        noise_pairs=195,
    )


def test_to_dict_is_the_calibrate_json_contract():
    report = a_fit().to_dict()
    assert report["params"] == {"alpha": 60.0, "c_zeta": 0.3, "c_psi": 0.2, "psi0_offset_deg": [0.6, -0.8],
                                "zeta0_offset": [0.004, -0.005]}  # fmt: skip
    assert report["stderr"] == {"alpha": 0.5, "c_zeta": 0.04, "c_psi": 0.02, "psi0_offset_deg": [0.09, 0.08],
                                "zeta0_offset": [math.inf, 0.0008]}  # fmt: skip
    assert report["parameters"] == list(PARAMETERS)
    assert report["unidentifiable"] == ["zeta0_offset.left"] and report["confounded"] == [["alpha", "c_zeta", 0.97]]
    assert report["outliers"] == [{"series": 2, "touchdown": 40, "residual": math.inf}]
    assert report["cut_at_fall"] == [{"series": 2, "touchdown": 41}]
    assert (report["touchdowns_used"], report["noise_pairs"], report["failed_predictions"]) == (200, 195, 1)
    assert (report["rms_residual_before"], report["rms_residual_after"]) == (0.17, 0.025)
    assert np.isnan(report["correlation"][5][0]) and report["correlation"][0][0] == 1.0
    json.dumps(report)  # plain lists and numbers (NaN and inf are the caller's to null)
