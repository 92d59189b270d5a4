"""The closed-loop benchmark as a study (experiments/control_study.py): the same outcome whatever
the chunking, the command line's JSON and the panel's plots from one result, names checked."""

import numpy as np
import pytest

from experiments.control_study import Config, check_controllers, laws_for, run
from sim_core.chunks import in_process
from sim_core.control.study import control_study
from sim_core.model.noise import NoiseModel
from sim_core.model.presets import get_preset
from sim_core.model.validation import ParameterError

ROBOT = get_preset("paper")
CONFIG = Config(controllers=("pid", "lqr"), jumps=150, seeds=14, seed0=7, noise=NoiseModel(pitch_drift_deg=2.0))


@pytest.fixture(scope="module")
def result():
    return run(ROBOT.to_model(), ROBOT.leg_length, CONFIG)


@pytest.mark.parametrize("chunk_seeds", [1, 5, 14])
def test_the_outcome_does_not_depend_on_the_chunks(result, chunk_seeds):
    calls = []

    def chunk_map(function, arguments, progress=None):
        calls.append(len(arguments))
        return in_process(function, arguments, progress)

    model = ROBOT.to_model()
    loop, laws = laws_for(model, CONFIG, ROBOT.leg_length)
    outcomes = control_study(model, laws, loop.start, 0.9, 150, 7, 14, CONFIG.noise, chunk_map=chunk_map,
                             chunk_seeds=chunk_seeds)  # fmt: skip
    assert calls == [2 * -(-14 // chunk_seeds)]
    for chunked, whole in zip(outcomes, result.outcomes, strict=True):
        assert chunked.failure_codes == whole.failure_codes and chunked.saturated == whole.saturated
        np.testing.assert_array_equal(chunked.height_errors, whole.height_errors)
        np.testing.assert_array_equal(chunked.failure_jumps, whole.failure_jumps)
        assert len(chunked.examples) == 3
        for a, b in zip(chunked.examples, whole.examples, strict=True):
            np.testing.assert_array_equal(a, b)


def test_the_json_and_the_plots_tell_the_same_study(result):
    payload, plots = result.to_dict(), result.plots()
    assert payload["seeds"] == [7, 14] and [entry["name"] for entry in payload["controllers"]] == ["pid", "lqr"]
    for entry, plot in zip(payload["controllers"], plots["controllers"], strict=True):
        curve = plot["failure_curve"]
        assert curve["jumps"][0] == 0 and curve["jumps"][-1] == 150 and curve["failures"][0] == 0
        assert curve["failures"][-1] == entry["failures"] and np.all(np.diff(curve["failures"]) >= 0)
        histogram = plot["height_error_histogram"]
        assert len(histogram["edges_m"]) == len(histogram["counts"]) + 1
        assert len(plot["examples"]) == 3
        # the first example is trial seed0's climb in metres, from its first touchdown
        assert 0.0 < plot["examples"][0][0] < payload["target_m"]
    pid = result.outcomes[0]
    assert pid.failures > 0, "pitch drift of 2 deg per jump should fail some PID runs within 150 jumps"
    assert sum(plots["controllers"][1]["height_error_histogram"]["counts"]) == result.outcomes[1].height_errors.size


@pytest.mark.parametrize(
    ("names", "says"),
    [
        ((), "must name at least one"),
        (("pid", "pid"), "twice"),
        (("deadbeat", "lqr", "deadbeat"), "twice"),
        (("mpc",), "'mpc'"),
    ],
)
def test_controllers_are_checked_by_name(names, says):
    with pytest.raises(ParameterError, match=says) as caught:
        check_controllers(names)
    assert caught.value.field == "controllers"
