"""Failure modes (sim_core.model.failures): the kernels' status codes, their stable names and messages."""

import pytest

from sim_core.model import failures
from sim_core.model.failures import OK, Failure

# Stored results refer to these: never renumber (docs/model.md §3.1).
STABLE = {"slip": 1, "collapse": 2, "no_liftoff": 3, "no_flight": 4, "invalid_state": 5, "floor": 6, "no_touchdown": 7}


def test_codes_and_numbers_are_the_stable_ones():
    assert {failure.code: int(failure) for failure in Failure} == STABLE
    assert OK == 0 and OK not in {int(failure) for failure in Failure}, "success is no failure"


def test_each_failure_is_its_kernel_status():
    for failure in Failure:
        status = getattr(failures, failure.name)
        assert Failure(status) is failure and status == failure.value


def test_from_code_reads_back_every_code():
    for failure in Failure:
        assert Failure.from_code(failure.code) is failure
    assert Failure.from_code("SLIP") is Failure.SLIP


def test_an_unknown_code_lists_the_known_ones():
    with pytest.raises(ValueError, match=r"^unknown failure code 'fell'; allowed: slip, collapse, no_liftoff"):
        Failure.from_code("fell")


def test_every_failure_has_its_own_sentence():
    messages = [failure.message for failure in Failure]
    assert len(set(messages)) == len(Failure) and all(message[0].islower() for message in messages)
    assert Failure.SLIP.message == "the leg left the friction cone (|tan psi| > mu) during stance"
