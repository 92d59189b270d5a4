"""The noise model (sim_core.model.noise): validation naming the field, the kernels' record and its units, seeds."""

import math
import subprocess
import sys
from dataclasses import fields

import numpy as np
import pytest

from sim_core import ParameterError
from sim_core.model.noise import ASYMMETRY_LIMITS, NO_NOISE, SIGMA_LIMITS, NoiseModel, NoiseRecord, trial_seeds


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("psi0_deg", -0.1),
        ("psi0_deg", 31.0),
        ("zeta0", 0.3),
        ("velocity", math.nan),
        ("pitch_drift_deg", -1.0),
        ("asymmetry_psi0_deg", 30.0),
        ("asymmetry_zeta0", -0.5),
    ],
)
def test_out_of_range_noise_names_its_field(field, value):
    with pytest.raises(ParameterError, match=rf"^noise\.{field}:"):
        NoiseModel(**{field: value})


def test_every_field_has_one_range_and_its_default_lies_in_it():
    """The ranges the API's request schema states (backend/schemas/jobs.py reads them from here)."""
    assert set(SIGMA_LIMITS) | set(ASYMMETRY_LIMITS) == set(NoiseModel().to_dict())
    assert not set(SIGMA_LIMITS) & set(ASYMMETRY_LIMITS)
    for field, limit in SIGMA_LIMITS.items():
        NoiseModel(**{field: 0.0})  # a sigma's range includes 0 ...
        with pytest.raises(ParameterError, match=rf"^noise\.{field}:"):
            NoiseModel(**{field: limit})  # ... and stops short of its limit
    for field, limit in ASYMMETRY_LIMITS.items():
        with pytest.raises(ParameterError, match=rf"^noise\.{field}:"):
            NoiseModel(**{field: -limit})


def test_the_kernels_record_is_in_radians_and_l0():
    noise = NoiseModel(1.0, 0.01, 0.02, 2.0, asymmetry_psi0_deg=-3.0, asymmetry_zeta0=0.005)
    record = noise.record()
    assert record == pytest.approx((math.radians(1.0), 0.01, 0.02, math.radians(2.0), math.radians(-3.0), 0.005))
    assert (record.sigma_pitch, record.asymmetry_zeta0) == (math.radians(2.0), 0.005)
    assert NoiseModel(**noise.to_dict()) == noise
    assert NO_NOISE.record() == (0.0,) * 6


def test_the_record_carries_every_field_of_the_noise_once():
    """One record field per NoiseModel field, in its order (a new disturbance needs both), each a
    float, so numba compiles one specialisation of every kernel whatever numbers are given."""
    assert len(NoiseRecord._fields) == len(fields(NoiseModel))
    record = NoiseModel(psi0_deg=1, zeta0=0, velocity=0, pitch_drift_deg=0).record()
    assert all(type(value) is float for value in record)


def test_trial_seeds_depend_on_seed_and_stream_only():
    first = trial_seeds(7, 0, 100)
    np.testing.assert_array_equal(first, trial_seeds(7, 0, 100))
    np.testing.assert_array_equal(first[:10], trial_seeds(7, 0, 10), err_msg="more trials extend fewer")
    assert len(set(first.tolist())) == 100
    assert not np.array_equal(first, trial_seeds(7, 1, 100))
    assert not np.array_equal(first, trial_seeds(8, 0, 100))
    with pytest.raises(ParameterError, match=r"^seed:"):
        trial_seeds(-1, 0, 3)


def test_the_model_loads_no_kernels():
    probe = "import sys, sim_core.model.noise; print('numba' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False", "sim_core.model.noise must stay light: the CLI reads its defaults"
