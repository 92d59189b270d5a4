"""The robot service's tracker slot: a new tracker is taken only once open; a failed connect gives
the working one back; a port that another program holds is named."""

import socket

import pytest

from backend.schemas import RobotConnect
from backend.services.robot_tracker import TrackerPortInUse, TrackerSlot
from sim_core.model.errors import ParameterError
from tests.helpers import free_port


def _request(port: int, host: str = "127.0.0.1") -> RobotConnect:
    return RobotConnect(url="loop://", tracker_host=host, tracker_port=port)


def test_a_new_tracker_on_the_working_ones_port_takes_its_place():
    slot, port = TrackerSlot(), free_port(socket.SOCK_DGRAM)
    slot.take(slot.open_beside(_request(port)), _request(port))
    first = slot.tracker
    again = slot.open_beside(_request(port))  # the working one gives way: the same port
    assert slot.tracker is None and again.address[1] == port
    slot.take(again, _request(port))
    assert slot.tracker is again and first is not again
    slot.close()


def test_a_failed_connect_gives_the_working_tracker_back_on_its_port():
    slot, port = TrackerSlot(), free_port(socket.SOCK_DGRAM)
    slot.take(slot.open_beside(_request(port)), _request(port))
    slot.give_up(slot.open_beside(_request(port)))
    assert slot.tracker is not None and slot.tracker.address[1] == port, "reopened as it was"
    other = free_port(socket.SOCK_DGRAM)
    working = slot.tracker
    slot.give_up(slot.open_beside(_request(other)))
    assert slot.tracker is working, "on another port the working one never closed"
    slot.close()


def test_a_port_another_program_holds_is_named_and_the_working_tracker_stays():
    slot, port = TrackerSlot(), free_port(socket.SOCK_DGRAM)
    slot.take(slot.open_beside(_request(port)), _request(port))
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as taken:
        taken.bind(("127.0.0.1", 0))
        held = taken.getsockname()[1]
        with pytest.raises(TrackerPortInUse, match=rf"tracker_port {held}: 127\.0\.0\.1:{held} is in use"):
            slot.open_beside(_request(held))
    assert slot.tracker is not None and slot.tracker.address[1] == port
    slot.close()


def test_an_address_this_machine_does_not_have_names_the_host():
    with pytest.raises(ParameterError, match=r"tracker_host: cannot listen on 192\.0\.2\.1"):
        TrackerSlot().open_beside(_request(free_port(socket.SOCK_DGRAM), host="192.0.2.1"))
