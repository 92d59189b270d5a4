"""What the robot link reports (backend/robot/link_types.py): its states as the robot's map onto
them, the states every ending must leave, transitions as the records store them, e-stop results."""

import dataclasses
import json

import pytest

from backend.robot import link, link_types
from backend.robot.link_types import FROM_ROBOT, SAFE, EstopResult, LinkState, Transition, telemetry_moves
from backend.robot.messages import RobotState


def test_every_robot_state_is_the_link_state_of_its_name():
    assert set(FROM_ROBOT) == set(RobotState), "a state the robot reports that the link cannot show"
    for robot_state, link_state in FROM_ROBOT.items():
        assert link_state.name == robot_state.name
    assert set(LinkState) - set(FROM_ROBOT.values()) == {LinkState.DISCONNECTED}, "the link's own state"


def test_only_disarmed_and_estopped_are_safe_endings():
    assert set(SAFE) == {RobotState.DISARMED, RobotState.ESTOPPED}
    assert not {RobotState.ARMED, RobotState.RUNNING} & set(SAFE), "a robot left armed or running is not safe"


def test_link_states_are_the_strings_the_api_shows():
    assert [state.value for state in LinkState] == ["disconnected", "disarmed", "armed", "running", "estopped"]
    assert json.dumps({"state": LinkState.ESTOPPED}) == '{"state": "estopped"}'


def test_a_transition_is_stored_with_its_states_as_strings():
    transition = Transition(1.7e9, LinkState.ARMED, LinkState.ESTOPPED, "e-stop")
    stored = transition.to_dict()
    assert stored == {"time": 1.7e9, "from": "armed", "to": "estopped", "reason": "e-stop"}
    assert json.loads(json.dumps(stored)) == stored


def test_an_estop_result_says_whether_and_when_it_was_acknowledged():
    assert EstopResult(True, 0.012).reason is None
    unacknowledged = EstopResult(False, 0.2, "no acknowledgement within 0.2 s")
    assert not unacknowledged.acknowledged and unacknowledged.reason.startswith("no acknowledgement")
    with pytest.raises(dataclasses.FrozenInstanceError):
        unacknowledged.acknowledged = True  # a result is what happened: it cannot be changed after


@pytest.mark.parametrize("name", ["LinkState", "LinkError", "EstopResult", "Transition"])
def test_callers_get_the_same_types_from_the_link(name):
    assert getattr(link, name) is getattr(link_types, name)


@pytest.mark.parametrize("reported", list(LinkState))
def test_an_estopped_link_under_the_latch_moves_only_for_the_reset_under_way(reported):
    assert telemetry_moves(LinkState.ESTOPPED, reported, latched=True, resetting=False) is False
    resetting = telemetry_moves(LinkState.ESTOPPED, reported, latched=True, resetting=True)
    assert resetting is (reported == LinkState.DISARMED)
    assert telemetry_moves(LinkState.ESTOPPED, reported, latched=False, resetting=False), "no latch: the robot's word"
    assert telemetry_moves(LinkState.ARMED, reported, latched=True, resetting=False), "e-stop not yet confirmed"
