"""The run's own channels of its MCAP recording (backend/services/mcap_schemas.py): topics in the
order they are registered, each a proto3 message of package ``parkourlab``, read back the way a
viewer reads them — from the schema's FileDescriptorSet, by mcap-protobuf-support's decoder."""

import io
import math

import pytest
from google.protobuf.descriptor import FieldDescriptor
from google.protobuf.descriptor_pb2 import FileDescriptorProto
from google.protobuf.json_format import MessageToDict
from mcap.reader import make_reader
from mcap.writer import Writer
from mcap_protobuf.decoder import DecoderFactory
from mcap_protobuf.schema import register_schema

from backend.services.mcap_schemas import MESSAGES, PACKAGE, TOPICS, encode, message_class

TOUCHDOWN = {"index": 0, "tracker_time": 1000.5, "wall": -1, "state": [-0.9, None], "body_height": 0.08,
             "foot_height": -0.02, "poses_fitted": 19, "control": None, "rise": None}  # fmt: skip


def read_back(topic: str, message: dict):
    """``message`` written on ``topic``'s channel as the export writes it, decoded by mcap-protobuf-support."""
    stream = io.BytesIO()
    writer = Writer(stream)
    writer.start()
    channel = writer.register_channel(topic, "protobuf", register_schema(writer, message_class(TOPICS[topic])))
    writer.add_message(channel, log_time=0, data=encode(topic, message), publish_time=0)
    writer.finish()
    reader = make_reader(io.BytesIO(stream.getvalue()), decoder_factories=[DecoderFactory()])
    ((schema, _channel, _message, decoded),) = reader.iter_decoded_messages()
    return schema, decoded


def test_channels_are_registered_in_this_order():
    assert list(TOPICS) == ["/tracker/pose", "/touchdowns", "/commands", "/telemetry", "/model/prediction",
                            "/robot/link"]  # fmt: skip
    assert set(TOPICS.values()) <= set(MESSAGES)


@pytest.mark.parametrize("name", MESSAGES)
def test_each_message_has_the_fields_its_spec_names(name):
    descriptor = message_class(name).DESCRIPTOR
    file = FileDescriptorProto()
    descriptor.file.CopyToProto(file)
    assert descriptor.full_name == f"{PACKAGE}.{name}" and file.syntax == "proto3"
    specs = [tuple(part.strip() for part in spec.split(":")) for spec in MESSAGES[name]]
    assert [field.name for field in descriptor.fields] == [field for field, _ in specs]
    assert [field.number for field in descriptor.fields] == list(range(1, len(specs) + 1))
    for field, (_, kind) in zip(descriptor.fields, specs, strict=True):
        repeated = field.is_repeated
        assert repeated == kind.endswith("[]"), field.name
        assert field.has_presence == (kind.endswith("?") or field.type == FieldDescriptor.TYPE_MESSAGE), field.name


def test_a_touchdown_reads_back_with_its_absent_values_absent():
    schema, decoded = read_back("/touchdowns", TOUCHDOWN)
    assert (schema.name, schema.encoding) == ("parkourlab.Touchdown", "protobuf")
    assert not decoded.HasField("rise") and not decoded.HasField("control"), "null: absent"
    assert decoded.state[0] == -0.9 and math.isnan(decoded.state[1]), "an unknown number: NaN"
    assert (decoded.wall, decoded.poses_fitted, decoded.tracker_time) == (-1, 19, 1000.5)
    later_one = TOUCHDOWN | {"index": 3, "rise": 0.57, "control": {"psi0_deg": 30.0, "zeta0": 0.9}}
    _, later = read_back("/touchdowns", later_one)
    assert (later.index, later.rise, later.control.psi0_deg, later.control.zeta0) == (3, 0.57, 30.0, 0.9)


def test_a_closed_loop_command_keeps_its_law():
    command = {"time": 1.8e9, "tracker_time": 1003.25, "leg": "right", "psi0_deg": 31.5, "zeta0": 0.91,
               "why": "pid after touchdown 2", "controller": "pid", "clipped": True, "state": [0.01, -0.2]}  # fmt: skip
    _, decoded = read_back("/commands", command)
    assert MessageToDict(decoded, preserving_proto_field_name=True) == command
    _, start = read_back("/commands", {**command, "tracker_time": None, "why": "start", "controller": None,
                                       "clipped": None, "state": []})  # fmt: skip
    assert not start.HasField("tracker_time") and not start.HasField("clipped") and not start.HasField("controller")


def test_a_key_the_message_does_not_have_is_left_out():
    link = {"time": 1.8e9, "from": "armed", "to": "running", "reason": "start"}
    _, decoded = read_back("/robot/link", link | {"seen_by": "nobody"})
    assert MessageToDict(decoded, preserving_proto_field_name=True) == link
