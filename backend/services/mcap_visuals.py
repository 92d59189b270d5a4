"""The channels of a run's MCAP recording that Foxglove and Rerun draw as they open it
(:mod:`backend.services.mcap_export` writes them beside the run's own channels of
:mod:`backend.services.mcap_schemas`; docs/service.md, "Recordings").

Each is derived from the run's own channels and adds nothing to them; it is there to be drawn (a
simulated run's recording, :mod:`backend.services.mcap_sim`, has those drawn from its body's path
and touchdowns only):

- the tracked body in Foxglove's own schemas, encoded as protobuf (``foxglove-schemas-protobuf``),
  which Foxglove's 3D panel and Rerun's MCAP importer (its ``foxglove`` decoder) both read:
  ``/tracker/pose_in_frame`` (``foxglove.PoseInFrame``; Rerun: ``InstancePoses3D`` and a
  ``CoordinateFrame``), ``/tracker/transform`` (``foxglove.FrameTransform`` from frame ``chute`` to
  frame ``body``; Rerun: ``Transform3D``) and ``/tracker/body`` (``foxglove.PointCloud`` of one
  point, the body; Rerun: ``Points3D``), one message per tracker frame;
- ``/world/scene`` (``foxglove.SceneUpdate``) and ``/world/points`` (``foxglove.PointCloud``; Rerun:
  ``Points3D``): the chute the run climbed, once at the start (:mod:`backend.services.mcap_world`);
- ``/robot/log`` (``foxglove.Log``; Rerun: ``TextLog``): a line per link change (a warning when the
  link is lost or the robot e-stopped) and per command sent, in the order they happened;
- number series as ROS 2 ``std_msgs/msg/Float64MultiArray`` (CDR) holding one number each, which
  Rerun's importer (its ``ros2msg`` decoder) turns into ``Scalars`` — a plot — and Foxglove's Plot
  panel reads as ``.data[0]``: the body's height per frame, and per touchdown the body's and the
  foot's height, the height gained and the model's prediction of it (:data:`SERIES`).

Why ROS 2 for the numbers: no Foxglove schema is a plain number, and Rerun 0.41 turns a protobuf
message of our own into a struct that a plot shows only once someone picks its fields by hand.

Frame ``chute``: x across the chute from its centre line [m], z up [m] (the wall's y), y = 0 (the
plane of the climb); a pitch counter-clockwise seen with x right and z up is a turn about -y.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Collection
from operator import methodcaller
from typing import TYPE_CHECKING

from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.PackedElementField_pb2 import PackedElementField
from foxglove_schemas_protobuf.PointCloud_pb2 import PointCloud
from foxglove_schemas_protobuf.PoseInFrame_pb2 import PoseInFrame
from foxglove_schemas_protobuf.Quaternion_pb2 import Quaternion
from foxglove_schemas_protobuf.Vector3_pb2 import Vector3
from google.protobuf.message import Message
from mcap_protobuf.schema import register_schema

from backend.services import mcap_world

if TYPE_CHECKING:
    from mcap.writer import Writer

POSE_FRAME = "chute"
BODY_FRAME = "body"

# topic -> Foxglove schema, in the order the channels are registered.
PROTOBUF_CHANNELS: dict[str, type[Message]] = {
    "/tracker/pose_in_frame": PoseInFrame,
    "/tracker/transform": FrameTransform,
    "/tracker/body": PointCloud,
    "/robot/log": Log,
    **mcap_world.CHANNELS,  # the chute the run climbed, written by mcap_export from mcap_world
}
WARNED_STATES = ("disconnected", "estopped")  # a link change into these is logged as a warning

# topic -> what its one number is, in the order the channels are registered.
SERIES: dict[str, str] = {
    "/plot/height": "the body's height [m], per tracker frame",
    "/plot/touchdown/body_height": "the body's height at each touchdown [m]",
    "/plot/touchdown/foot_height": "the foot's height at each touchdown [m]",
    "/plot/touchdown/rise": "the height gained from the touchdown before [l0], from the second touchdown on",
    "/plot/prediction/rise": "the model's prediction of that gain [l0] (none with fewer than two touchdowns)",
}

SERIES_SCHEMA = "std_msgs/msg/Float64MultiArray"
# The message definition as ROS 2 records it in MCAP: the type, then each type it uses.
SERIES_MSGDEF = """\
std_msgs/MultiArrayLayout layout
float64[] data
================================================================================
MSG: std_msgs/MultiArrayLayout
std_msgs/MultiArrayDimension[] dim
uint32 data_offset
================================================================================
MSG: std_msgs/MultiArrayDimension
string label
uint32 size
uint32 stride
"""
# CDR, little-endian: the encapsulation header (CDR_LE), then the fields, each aligned to its size
# counted from the end of the header: an empty layout (no dim, data_offset 0), data's length (1),
# 4 bytes of padding, the float64.
_SERIES_CDR = struct.Struct("<4sIII4xd")
_CDR_LE = b"\x00\x01\x00\x00"


def drawn(messages: dict[str, list[tuple[int, dict]]]) -> dict[str, list[tuple[int, object]]]:
    """This module's channels, topic -> [(log time [ns], message)], from the run's own channels
    (field dicts; times kept): protobuf messages for :data:`PROTOBUF_CHANNELS`, floats for :data:`SERIES`.
    A channel drawn from channels the run does not have is left out: ``/robot/log`` without
    ``/robot/link`` and ``/commands``, ``/plot/prediction/rise`` without ``/model/prediction`` (a
    simulation's recording)."""
    poses = messages.get("/tracker/pose", [])
    touchdowns = messages.get("/touchdowns", [])
    drawings = {
        "/tracker/pose_in_frame": [(time, pose_in_frame(time, pose)) for time, pose in poses],
        "/tracker/transform": [(time, body_transform(time, pose)) for time, pose in poses],
        "/tracker/body": [(time, body_point(time, pose)) for time, pose in poses],
    }
    if "/robot/link" in messages or "/commands" in messages:
        drawings["/robot/log"] = robot_log(messages.get("/robot/link", []), messages.get("/commands", []))
    drawings |= {
        "/plot/height": [(time, pose["y"]) for time, pose in poses],
        "/plot/touchdown/body_height": [(time, td["body_height"]) for time, td in touchdowns],
        "/plot/touchdown/foot_height": [(time, td["foot_height"]) for time, td in touchdowns],
        "/plot/touchdown/rise": [(time, td["rise"]) for time, td in touchdowns if td["rise"] is not None],
    }
    if "/model/prediction" in messages:
        predictions = messages["/model/prediction"]
        drawings["/plot/prediction/rise"] = [(time, p["rise"]) for time, p in predictions if p["rise"] is not None]
    return drawings


def register(writer: Writer, topics: Collection[str]) -> dict[str, tuple[int, Callable[[object], bytes]]]:
    """Register this module's schemas and channels that are among ``topics`` on ``writer``, in
    order; topic -> (channel id, the function that encodes one of its messages)."""
    channels: dict[str, tuple[int, Callable[[object], bytes]]] = {}
    for topic, schema in PROTOBUF_CHANNELS.items():
        if topic in topics:
            channel_id = writer.register_channel(topic, "protobuf", register_schema(writer, schema))
            channels[topic] = (channel_id, methodcaller("SerializeToString"))
    series = [topic for topic in SERIES if topic in topics]
    if series:
        series_schema = writer.register_schema(SERIES_SCHEMA, "ros2msg", SERIES_MSGDEF.encode())
        for topic in series:
            channels[topic] = (writer.register_channel(topic, "cdr", series_schema), series_cdr)
    return channels


def pose_in_frame(time_ns: int, pose: dict) -> PoseInFrame:
    """A tracker pose (``/tracker/pose``'s message) as ``foxglove.PoseInFrame`` in frame ``chute``."""
    message = PoseInFrame(frame_id=POSE_FRAME)
    message.timestamp.FromNanoseconds(time_ns)
    message.pose.position.CopyFrom(_position(pose))
    message.pose.orientation.CopyFrom(_orientation(pose))
    return message


def body_transform(time_ns: int, pose: dict) -> FrameTransform:
    """The same pose as the transform from frame ``chute`` to frame ``body``."""
    message = FrameTransform(parent_frame_id=POSE_FRAME, child_frame_id=BODY_FRAME)
    message.timestamp.FromNanoseconds(time_ns)
    message.translation.CopyFrom(_position(pose))
    message.rotation.CopyFrom(_orientation(pose))
    return message


def body_point(time_ns: int, pose: dict) -> PointCloud:
    """The body as a cloud of one point in frame ``chute`` (float64 x, y, z)."""
    message = PointCloud(
        frame_id=POSE_FRAME,
        point_stride=24,
        fields=[PackedElementField(name=axis, offset=8 * i, type=PackedElementField.FLOAT64) for i, axis in
                enumerate("xyz")],
        data=struct.pack("<3d", pose["x"], 0.0, pose["y"]),
    )  # fmt: skip
    message.timestamp.FromNanoseconds(time_ns)
    message.pose.position.SetInParent()  # the identity pose, written out: the origin ...
    message.pose.orientation.w = 1.0  # ... and no turn
    return message


def robot_log(transitions: list[tuple[int, dict]], commands: list[tuple[int, dict]]) -> list[tuple[int, Log]]:
    """Link changes and commands (``/robot/link``'s and ``/commands``' messages) as log lines, in time order."""
    lines = [
        (
            time,
            Log.WARNING if change["to"] in WARNED_STATES else Log.INFO,
            "robot/link",
            f"link {change['from']} -> {change['to']}: {change['reason']}",
        )
        for time, change in transitions
    ]
    lines += [(time, Log.INFO, "commands", f"{command['leg']} leg psi0 {command['psi0_deg']:.3f} deg, zeta0 "
               f"{command['zeta0']:.4f} l0: {command['why']}") for time, command in commands]  # fmt: skip
    return [
        (time, _log(time, level, name, text)) for time, level, name, text in sorted(lines, key=lambda line: line[0])
    ]


def _log(time_ns: int, level: int, name: str, text: str) -> Log:
    message = Log(level=level, name=name, message=text)
    message.timestamp.FromNanoseconds(time_ns)
    return message


def series_cdr(value: object) -> bytes:
    """One number as a CDR-encoded ``std_msgs/msg/Float64MultiArray`` (``data == [value]``)."""
    return _SERIES_CDR.pack(_CDR_LE, 0, 0, 1, float(value))


def _position(pose: dict) -> Vector3:
    return Vector3(x=pose["x"], y=0.0, z=pose["y"])


def _orientation(pose: dict) -> Quaternion:
    """The pitch (0 where the tracker gave none) as a turn about -y."""
    half = 0.5 * (pose["pitch"] or 0.0)
    return Quaternion(x=0.0, y=-math.sin(half), z=0.0, w=math.cos(half))
