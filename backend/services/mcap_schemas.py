"""The run's own channels of its MCAP recording (:mod:`backend.services.mcap_export`): topic and
protobuf message of each, in the order they are registered (the channels drawn in Foxglove's and
Rerun's own formats are :mod:`backend.services.mcap_visuals`).

Protobuf (``message_encoding="protobuf"``, the schema a ``FileDescriptorSet``), not JSON: Rerun's
MCAP importer (0.41) shows a JSON channel as each message's bytes whatever its JSON Schema says,
while it decodes any protobuf message into a struct of its fields; Foxglove and the ``mcap`` tools
read both. The messages are proto3 in package ``parkourlab``, built here from :data:`MESSAGES`
(no generated code to keep in step): each field is ``name: type`` with type ``double``,
``uint32``, ``sint32``, ``bool``, ``string`` or a message of the package; ``?`` after it: it may
be absent (proto3 ``optional``; JSON's null), ``[]``: repeated (NaN for an unknown number).

Units: SI (metres, seconds, radians) unless a name says degrees (``_deg``) or below says
otherwise: section states in sqrt(g l0), height gains and leg lengths in l0. Times: ``time``
Unix time [s] of this PC, ``tracker_time`` the tracker's time [s] (a command's and a telemetry's:
the newest frame's when it was sent or heard; absent before the run's first frame, and in runs
stored before it was recorded). A message's log time is on the tracker's clock
(:mod:`backend.services.mcap_clock`).
"""

from __future__ import annotations

import math
from functools import cache

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from google.protobuf.descriptor_pb2 import FieldDescriptorProto as Field
from google.protobuf.message import Message

PACKAGE = "parkourlab"

# message -> its fields in order (field number = place + 1). Units: the module's docstring.
MESSAGES: dict[str, tuple[str, ...]] = {
    # One tracker frame: the body in wall coordinates, x across the chute from its centre line, y up
    # [m]; pitch [rad] counter-clockwise with x right and y up, absent where the markers gave none.
    "TrackerPose": ("tracker_time: double", "x: double", "y: double", "pitch: double?"),
    # A leg's touchdown angle [deg] and length [l0].
    "Control": ("psi0_deg: double", "zeta0: double"),
    # A detected touchdown: wall -1 left, 1 right; state (xdot, ydot) [sqrt(g l0)] flipped to the left
    # wall; heights [m]; the controls it was made with; rise: the height gained from the one before
    # [l0] (absent for the first).
    "Touchdown": ("index: uint32", "tracker_time: double", "wall: sint32", "state: double[]", "body_height: double",
                  "foot_height: double", "poses_fitted: uint32", "control: Control?", "rise: double?"),
    # A leg command the PC sent: leg "left" or "right"; why: "start" or the law's step that chose it;
    # closed loop, the law (controller), whether it was clipped, and its state after the step.
    "Command": ("time: double", "tracker_time: double?", "leg: string", "psi0_deg: double", "zeta0: double",
                "why: string", "controller: string?", "clipped: bool?", "state: double[]"),
    # A TELEMETRY message from the robot (docs/protocol.md): the servos' leg angles [deg] and lengths
    # [l0], left and right; battery [mV]; faults (bits).
    "Telemetry": ("time: double", "tracker_time: double?", "seq: uint32", "state: string", "psi_servo_deg: double[]",
                  "zeta_servo: double[]", "battery_mv: uint32", "faults: uint32"),
    # The model's prediction of touchdown index (0: the measured start), the Poincaré map iterated with
    # the measured controls (in a stored world, the model's climb there: metadata prediction_model),
    # beside what was measured; rises [l0] absent for touchdown 0.
    "Prediction": ("index: uint32", "state: double[]", "measured_state: double[]", "rise: double?",
                   "measured_rise: double?"),
    # A change of the robot link's state.
    "LinkTransition": ("time: double", "from: string", "to: string", "reason: string"),
}  # fmt: skip

# topic -> message name, in the order the channels are registered.
TOPICS: dict[str, str] = {
    "/tracker/pose": "TrackerPose",
    "/touchdowns": "Touchdown",
    "/commands": "Command",
    "/telemetry": "Telemetry",
    "/model/prediction": "Prediction",
    "/robot/link": "LinkTransition",
}

_SCALARS = {
    "double": Field.TYPE_DOUBLE,
    "uint32": Field.TYPE_UINT32,
    "sint32": Field.TYPE_SINT32,
    "bool": Field.TYPE_BOOL,
    "string": Field.TYPE_STRING,
}


def file_descriptor() -> descriptor_pb2.FileDescriptorProto:
    """:data:`MESSAGES` as one proto3 file, ``parkourlab/recording.proto``."""
    proto = descriptor_pb2.FileDescriptorProto(name="parkourlab/recording.proto", package=PACKAGE, syntax="proto3")
    for name, fields in MESSAGES.items():
        message = proto.message_type.add(name=name)
        for number, spec in enumerate(fields, start=1):
            field_name, kind = (part.strip() for part in spec.split(":"))
            base = kind.rstrip("?[]")
            field = message.field.add(name=field_name, number=number)
            field.label = Field.LABEL_REPEATED if kind.endswith("[]") else Field.LABEL_OPTIONAL
            if base in _SCALARS:
                field.type = _SCALARS[base]
            else:
                field.type, field.type_name = Field.TYPE_MESSAGE, f".{PACKAGE}.{base}"
            if kind.endswith("?") and base in _SCALARS:  # a message field has presence already
                field.proto3_optional = True
                field.oneof_index = len(message.oneof_decl)
                message.oneof_decl.add(name=f"_{field_name}")
    return proto


@cache
def message_class(name: str) -> type[Message]:
    """The protobuf class of message ``name`` of :data:`MESSAGES` (one pool, built once)."""
    return message_factory.GetMessageClass(_pool().FindMessageTypeByName(f"{PACKAGE}.{name}"))


def encode(topic: str, message: dict) -> bytes:
    """A channel's message, given as a dict of its fields (None: absent; a key the message does not
    have is left out), serialised as its protobuf message."""
    cls = message_class(TOPICS[topic])
    fields = cls.DESCRIPTOR.fields_by_name
    return cls(**{key: _nan_for_none(value) for key, value in message.items() if key in fields}).SerializeToString()


def _nan_for_none(value: object) -> object:
    """A list's unknown numbers (JSON keeps NaN as null) as NaN: a repeated double has no null."""
    return [math.nan if item is None else item for item in value] if isinstance(value, list) else value


@cache
def _pool() -> descriptor_pool.DescriptorPool:
    pool = descriptor_pool.DescriptorPool()
    pool.Add(file_descriptor())
    return pool
