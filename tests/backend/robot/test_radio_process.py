"""The radio process' own rules, on a clock the tests give it: the cadence writes only while the
service's lease holds, an e-stop's write takes the queue back, a service faster than the cadence
keeps the queue bounded, and a request it does not know is answered, not a crash. The process as a
whole (started, ended, outliving nothing) is in test_process_port.py; against a stalled service, in
test_link_keeps_time.py."""

import serial

from backend.robot import radio_process as radio
from backend.robot.messages import Command, Kind, decode, encode
from backend.robot.xbee import ROBOT_ADDRESS, FrameParser, parse_tx_request

NOW = 1000.0  # [s] the tests' monotonic clock


def a_radio() -> radio.Radio:
    return radio.Radio(serial.serial_for_url("loop://", baudrate=57_600, timeout=0), ROBOT_ADDRESS)


def written(port) -> list:
    """The messages written on a loop:// port (it echoes them), in order."""
    return [decode(parse_tx_request(frame)[2]) for frame in FrameParser().feed(port.read(65536))]


def heartbeat(seq: int) -> bytes:
    return encode(Command(seq, Kind.HEARTBEAT))


def request(kind: bytes, stamp: float, payload: bytes = b"", number: int = 7) -> bytes:
    return kind + radio.HEAD.pack(number, stamp) + payload


def answered(answer: bytes) -> tuple[int, int, int, int, str]:
    """(status, frames out, write timeouts, queued, reason) of the answer to request number 7."""
    number, *counts = radio.ANSWER.unpack_from(answer)
    assert number == 7, "each answer names its request"
    return (*counts, answer[radio.ANSWER.size :].decode())


def test_the_cadence_writes_the_queued_frames_in_order_while_the_lease_holds():
    box = a_radio()
    for seq in (1, 2, 3):
        box.queue_frame(NOW + radio.LEASE, heartbeat(seq))
    assert box.beat(NOW) and box.beat(NOW + 0.1)
    assert not box.beat(NOW + radio.LEASE), "the lease has run out: the last frame stays unwritten"
    assert [message.seq for message in written(box.port)] == [1, 2] and box.frames_out == 2
    box.queue_frame(NOW + 1.0 + radio.LEASE, heartbeat(4))  # the service is back: its frame renews the lease
    assert box.beat(NOW + 1.0) and box.beat(NOW + 1.1) and not box.beat(NOW + 1.2), "the queue is empty"
    assert [message.seq for message in written(box.port)] == [3, 4]


def test_a_service_faster_than_the_cadence_keeps_the_queue_bounded_and_the_lease_never_shrinks():
    box = a_radio()
    for seq in range(1, 4 * radio.LEASE_FRAMES):
        box.queue_frame(NOW + radio.LEASE - 0.01 * seq, heartbeat(seq))  # an answer delayed: a shorter lease
    assert len(box.queue) == 2 * radio.LEASE_FRAMES, "the oldest frames go"
    assert box.lease_until == NOW + radio.LEASE - 0.01, "the latest renewal does not cut the lease short"
    assert box.beat(NOW) and written(box.port)[0].seq == 2 * radio.LEASE_FRAMES


def test_an_estops_write_takes_the_queue_back_first():
    box = a_radio()
    for seq in (1, 2):
        assert answered(radio.handle(box, request(radio.QUEUE, NOW + radio.LEASE, heartbeat(seq))))[3] == seq
    estop = encode(Command(9, Kind.ESTOP))
    status, frames_out, timeouts, queued, reason = answered(radio.handle(box, request(radio.WRITE_ALONE, 1e12, estop)))
    assert (status, frames_out, timeouts, queued, reason) == (radio.OK, 1, 0, 0, "")
    assert not box.beat(NOW), "no heartbeat follows the e-stop"
    assert [(message.kind, message.seq) for message in written(box.port)] == [(Kind.ESTOP, 9)]


def test_a_plain_write_keeps_the_queue_and_a_drop_empties_it():
    box = a_radio()
    radio.handle(box, request(radio.QUEUE, NOW + radio.LEASE, heartbeat(1)))
    assert answered(radio.handle(box, request(radio.WRITE, 1e12, encode(Command(2, Kind.ARM)))))[3] == 1
    assert answered(radio.handle(box, request(radio.DROP, 0.0)))[3] == 0 and not box.beat(NOW)
    assert [message.kind for message in written(box.port)] == [Kind.ARM]


def test_a_write_on_a_closed_port_is_answered_with_its_reason():
    box = a_radio()
    box.port.close()
    status, frames_out, *_rest, reason = answered(radio.handle(box, request(radio.WRITE, 1e12, heartbeat(1))))
    assert status == radio.FAILED_WRITE and frames_out == 0 and reason


def test_an_unknown_request_is_answered_not_obeyed():
    box = a_radio()
    status, *_counts, reason = answered(radio.handle(box, request(b"Z", NOW, heartbeat(1))))
    assert status == radio.FAILED_WRITE and "unknown request b'Z'" in reason and written(box.port) == []
