"""``parkour mfpt --controller`` (cli/mfpt_loop.py): the JSON contract, and one line naming the option."""

import pytest

from tests.cli.helpers import invoke, json_of

QUICK = ("--runs", "2", "--replicas", "20", "--pitch-drift", "0", "--noise-velocity", "0.05")


def test_a_controllers_mfpt_keeps_the_chains_keys():
    payload = json_of("mfpt", "--controller", "pid", "--target", "0.5", *QUICK)
    assert {"mfpt_jumps", "lambda2", "discretisation_error", "cells", "seconds"} <= set(payload)
    assert payload["method"] == "splitting" and payload["controller"] == "pid" and payload["target_m"] == 0.5
    assert payload["mfpt_jumps"] > 1 and 0 < payload["lambda2"] < 1 and payload["noise"]["velocity"] == 0.05
    assert payload["splitting"]["runs"] == 2 and payload["splitting"]["replicas"] == 20


def test_the_words_say_an_interval_open_above():
    """Two runs: the t interval on the rate reaches 0, so its upper end is infinite (null in JSON)."""
    result = invoke("mfpt", "--controller", "pid", *QUICK)
    assert result.exit_code == 0, result.output
    assert result.output.startswith("pid: MFPT ") and "- inf), lambda2 " in result.output


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ("--controller", "pd", "--pitch-drift", "0"),
            "--controller: must be one of pid, pid-pitch, lqr, deadbeat, placement",
        ),
        (("--controller", "lqr"), "--pitch-drift: must be 0 for a controller's MFPT"),
        (("--controller", "lqr", "--pitch-drift", "0", "--target", "9"), "--target: must be in (0, 2]"),
        (("--controller", "lqr", "--pitch-drift", "0", "--runs", "1"), "--runs: must be in [2, 1000], got 1"),
        (("--controller", "lqr", "--grid", "20"), "--grid: applies to the chain of fixed controls"),
        (("--controller", "lqr", "--no-cache"), "--no-cache: applies to the chain of fixed controls"),
        (("--controller", "lqr", "--controls", "35:0.9,30:0.9"), "--controls: with --controller, one PSI0:ZETA0"),
        (
            (
                "--target",
                "0.5",
            ),
            "--target: needs --controller",
        ),
        (
            (
                "--seed",
                "3",
            ),
            "--seed: needs --controller",
        ),
    ],
)
def test_what_it_cannot_take_is_one_line_naming_the_option(args, message):
    result = invoke("mfpt", *args)
    assert result.exit_code == 2, result.output
    assert message in result.output
