"""The JSON channels of a run's MCAP recording (:mod:`backend.services.mcap_export`): topic,
schema name and JSON Schema of each, in the order they are registered (the channels drawn in
Foxglove's and Rerun's own formats are :mod:`backend.services.mcap_visuals`).

These channels' messages are JSON (``message_encoding="json"``) and their schemas JSON Schemas
(``encoding="jsonschema"``), so Foxglove, Rerun and the ``mcap`` tools read them without code of
ours. Units: SI (metres, seconds, radians) unless a name says degrees (``_deg``) or the field
says nondimensional (section states in sqrt(g l0), height gains in l0). Times inside a message
are the clock that took them: ``tracker_time`` the tracker's [s], ``time`` Unix time [s]; a
message's MCAP log and publish time is in UTC nanoseconds (the module above says how).
"""

from __future__ import annotations

NUMBER = {"type": "number"}
NUMBER_OR_NULL = {"type": ["number", "null"]}
INTEGER = {"type": "integer"}
STRING = {"type": "string"}
SECTION_STATE = {
    "type": "array",
    "items": NUMBER_OR_NULL,
    "minItems": 2,
    "maxItems": 2,
    "description": "(xdot, ydot) at touchdown [sqrt(g l0)], flipped to the left wall",
}
CONTROL = {
    "type": ["object", "null"],
    "properties": {"psi0_deg": NUMBER, "zeta0": NUMBER},
    "required": ["psi0_deg", "zeta0"],
    "description": "a leg's touchdown angle [deg] and length [l0]; null where not recorded",
}


def _object(title: str, description: str, properties: dict, required: list[str] | None = None) -> dict:
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": title,
        "description": description,
        "type": "object",
        "properties": properties,
        "required": list(properties) if required is None else required,
    }


TRACKER_POSE = _object(
    "parkourlab.TrackerPose",
    "One tracker frame: the body in wall coordinates (x across the chute from its centre line, y up)",
    {
        "tracker_time": {**NUMBER, "description": "the tracker's own time of the frame [s]"},
        "x": {**NUMBER, "description": "[m] across the chute, from its centre line"},
        "y": {**NUMBER, "description": "[m] up"},
        "pitch": {**NUMBER_OR_NULL, "description": "[rad] counter-clockwise (x right, y up); null if untracked"},
    },
)

TOUCHDOWN = _object(
    "parkourlab.Touchdown",
    "A detected touchdown: its section state, heights, the controls it was made with, the height gained",
    {
        "index": {**INTEGER, "description": "0-based touchdown number"},
        "tracker_time": {**NUMBER, "description": "[s] the tracker's time of the touchdown"},
        "wall": {"type": "integer", "enum": [-1, 1], "description": "-1 the left wall, 1 the right"},
        "state": SECTION_STATE,
        "body_height": {**NUMBER, "description": "[m]"},
        "foot_height": {**NUMBER, "description": "[m]"},
        "poses_fitted": INTEGER,
        "control": CONTROL,
        "rise": {**NUMBER_OR_NULL, "description": "height gain from the touchdown before [l0]; null for the first"},
    },
)

COMMAND = _object(
    "parkourlab.Command",
    "A leg command the PC sent the robot",
    {
        "time": {**NUMBER, "description": "Unix time it was sent [s]"},
        "leg": {"type": "string", "enum": ["left", "right"]},
        "psi0_deg": NUMBER,
        "zeta0": NUMBER,
        "why": {**STRING, "description": "'start', or the PID step that chose it"},
    },
)

_LEFT_RIGHT = {"type": "array", "items": NUMBER, "minItems": 2, "maxItems": 2}
TELEMETRY = _object(
    "parkourlab.Telemetry",
    "A TELEMETRY message from the robot (docs/protocol.md)",
    {
        "time": {**NUMBER, "description": "Unix time it was received [s]"},
        "seq": INTEGER,
        "state": STRING,
        "psi_servo_deg": {**_LEFT_RIGHT, "description": "the servos' leg angles, left and right [deg]"},
        "zeta_servo": {**_LEFT_RIGHT, "description": "the servos' leg lengths, left and right [l0]"},
        "battery_mv": {**INTEGER, "description": "[mV]"},
        "faults": INTEGER,
    },
)

PREDICTION = _object(
    "parkourlab.Prediction",
    "The model's prediction of touchdown k: the Poincaré map iterated from the first measured touchdown with the"
    " measured controls, beside the measured state",
    {
        "index": {**INTEGER, "description": "the touchdown predicted (0 is the measured start)"},
        "state": SECTION_STATE,
        "measured_state": SECTION_STATE,
        "rise": {**NUMBER_OR_NULL, "description": "predicted height gain into this touchdown [l0]; null for 0"},
        "measured_rise": {**NUMBER_OR_NULL, "description": "measured height gain into this touchdown [l0]"},
    },
)

LINK = _object(
    "parkourlab.LinkTransition",
    "A change of the robot link's state",
    {
        "time": {**NUMBER, "description": "Unix time of the change [s]"},
        "from": STRING,
        "to": STRING,
        "reason": STRING,
    },
)

# topic -> schema, in the order the channels are registered.
CHANNELS: dict[str, dict] = {
    "/tracker/pose": TRACKER_POSE,
    "/touchdowns": TOUCHDOWN,
    "/commands": COMMAND,
    "/telemetry": TELEMETRY,
    "/model/prediction": PREDICTION,
    "/robot/link": LINK,
}
