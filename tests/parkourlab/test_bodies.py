"""parkourlab/bodies.py: what a script writes (``(psi0, zeta0)`` legs, ``(xdot, ydot)`` states) as the
API's request bodies take it, and the service's defaults left to it (None values left out)."""

from __future__ import annotations

from types import MappingProxyType

import pytest

from parkourlab.bodies import legs, mapping, present, state


def test_legs_from_pairs_and_mappings_in_order():
    given = [(30, 0.87), {"psi0_deg": 31.5, "zeta0": 0.9}, [29, 0.88]]
    assert legs(given) == [
        {"psi0_deg": 30, "zeta0": 0.87},
        {"psi0_deg": 31.5, "zeta0": 0.9},
        {"psi0_deg": 29, "zeta0": 0.88},
    ]
    assert legs(((30, 0.9),)) == [{"psi0_deg": 30, "zeta0": 0.9}]
    assert legs([]) == []


def test_legs_are_copies():
    mine = {"psi0_deg": 30, "zeta0": 0.9}
    (sent,) = legs([MappingProxyType(mine)])
    assert type(sent) is dict and sent == mine
    sent["zeta0"] = 0.5
    assert mine["zeta0"] == 0.9, "the caller's mapping is not the body's"


def test_state_from_a_pair_or_a_mapping():
    assert state((-0.93, -0.17)) == {"xdot": -0.93, "ydot": -0.17}
    assert state([-0.93, 0.0]) == {"xdot": -0.93, "ydot": 0.0}
    mine = {"xdot": -0.9, "ydot": 0.1}
    sent = state(MappingProxyType(mine))
    assert type(sent) is dict and sent == mine and sent is not mine
    assert state(None) is None


def test_a_pair_too_short_is_an_error_not_a_half_body():
    with pytest.raises(IndexError):
        legs([(30,)])
    with pytest.raises(IndexError):
        state((-0.9,))


def test_mapping_a_plain_dict_or_none():
    proxy = MappingProxyType({"preset": "paper", "mu": 0.8})
    plain = mapping(proxy)
    assert type(plain) is dict and plain == {"preset": "paper", "mu": 0.8}
    assert mapping(None) is None and mapping({}) == {}


def test_present_drops_only_none():
    body = {"jumps": None, "trials": 0, "fixed_point": False, "notes": "", "tags": [], "seed": 1}
    assert present(body) == {"trials": 0, "fixed_point": False, "notes": "", "tags": [], "seed": 1}
    assert list(present({"b": 1, "a": None, "c": 2})) == ["b", "c"], "order kept"
    assert present({}) == {}


def test_the_api_takes_the_bodies():
    from backend.schemas import LegIn, StateIn

    for leg in legs([(30, 0.87), {"psi0_deg": 30, "zeta0": 0.9}]):
        LegIn.model_validate(leg)  # strict: a misnamed key is refused
    StateIn.model_validate(state((-0.93, -0.17)))
