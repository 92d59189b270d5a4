"""A controller's MFPT as the control study sets its climb up (experiments/loop_mfpt.py)."""

import pytest

from experiments.loop_mfpt import Config, run
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.model.validation import ParameterError
from sim_core.robustness.splitting import SplittingOptions

ROBOT = get_preset("paper")
QUICK = SplittingOptions(replicas=20, runs=2, pilot_jumps=2_000, climbs=20)


def test_the_payload_names_the_climb_and_the_law():
    config = Config(controller="lqr", target_m=0.5, noise=NoiseModel(velocity=0.05, pitch_drift_deg=0.0), options=QUICK)
    payload = run(ROBOT.to_model(), ROBOT.leg_length, config)
    assert payload["controller"] == "lqr" and payload["target_m"] == 0.5 and payload["method"] == "splitting"
    assert payload["controls"] == {"psi0_deg": 35.0, "zeta0": 0.9} and len(payload["start"]) == 2
    assert payload["mfpt_jumps"] > payload["splitting"]["climb_jumps"] > 0


@pytest.mark.parametrize(
    ("config", "field"),
    [
        (Config(controller="pd"), "controllers"),
        (Config(target_m=5.0), "target"),
        (Config(noise=NoiseModel()), "noise.pitch_drift_deg"),
    ],
)
def test_what_it_cannot_take_names_the_field(config, field):
    with pytest.raises(ParameterError) as caught:
        run(ROBOT.to_model(), ROBOT.leg_length, config)
    assert caught.value.field == field
