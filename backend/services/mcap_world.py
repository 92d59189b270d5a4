"""The chute a run climbed, drawn in its MCAP recording (docs/service.md, "Recordings"), beside the
body of :mod:`backend.services.mcap_visuals`, in its frame ``chute`` (x across the chute from its
centre line [m], z up [m], y = 0 the plane of the climb). Each is one message at the recording's
start:

- ``/world/scene`` (``foxglove.SceneUpdate``), which Foxglove's 3D panel draws: one entity per side
  (id ``left``, ``right``; ``frame_locked``, no lifetime: it stays for the whole recording) holding a
  slab (``CubePrimitive``) per segment, whose inner face is the segment and which stands
  :data:`DEPTH` deep across the plane of the climb, coloured by its friction as the panel's World
  tab colours it (:func:`mu_color`); a foothold — a segment with grip — is :data:`FOOTHOLD` thick
  and opaque, a segment without grip (mu = 0) :data:`NO_GRIP` thick and translucent; and a
  ``LINE_STRIP`` through the side's vertices (its surface). The entity's metadata: ``side``,
  ``world``, ``mu`` (each segment's entry as a world file writes it, JSON) and ``footholds`` (their
  indices, JSON).
- ``/world/points`` (``foxglove.PointCloud``): the same sides as points along their segments (a
  vertex, then every :data:`SOLID` [m] along a foothold, every :data:`DOTTED` [m] along a segment
  without grip; each side's last vertex too), float64 x, y, z and uint8 red, green, blue, alpha in
  the slabs' colours. Rerun 0.41's importer draws no ``SceneUpdate`` (it keeps the message as a
  struct at ``/world/scene``) but draws this as coloured ``Points3D``.

Which chute: the run's stored world (``runs.world_id``; a replay's, its source run's; a simulated
run's, its own), read with the robot's leg length (:data:`ROBOT_PRESET`'s: the run stores its
nondimensional model only); a run without one climbed parallel walls — every run stored before
worlds — drawn as two vertical walls ``d_hat l0`` apart (its model's ``d_hat``) with the model's
``mu``, from the floor to a leg length above the body's highest frame. Past a world's first and
last vertices a side goes on as a vertical wall with the model's ``mu`` (docs/model.md §8); that is
not drawn.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.CubePrimitive_pb2 import CubePrimitive
from foxglove_schemas_protobuf.LinePrimitive_pb2 import LinePrimitive
from foxglove_schemas_protobuf.PackedElementField_pb2 import PackedElementField
from foxglove_schemas_protobuf.PointCloud_pb2 import PointCloud
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from sqlalchemy.orm import Session

from backend.repositories import worlds as stored_worlds
from backend.store.models import Run
from sim_core.model.presets import get_preset
from sim_core.world.files import world_from_document
from sim_core.world.world import SIDES, Side, World, parallel

FRAME = "chute"
CHANNELS = {"/world/scene": SceneUpdate, "/world/points": PointCloud}  # topic -> Foxglove schema
ROBOT_PRESET = "paper"  # the robot of the service's robot runs and replays (RobotService, replay_run); mcap_sim's scale
DEPTH = 0.2  # [m] a slab's extent across the plane of the climb (along y)
FOOTHOLD, NO_GRIP = 0.02, 0.005  # [m] a slab's thickness, into the wall
FOOTHOLD_ALPHA, NO_GRIP_ALPHA = 1.0, 0.35
SOLID, DOTTED = 0.005, 0.02  # [m] between points along a foothold, a segment without grip
LINE_WIDTH = 2.0  # [px] the surface's line (scale invariant)
# The panel's World tab's scale (frontend/panel/world_draw.js): reversed viridis from mu = 0 (light)
# to MU_TOP and above (dark); the model's mu grey, no slip near black.
MU_TOP = 3.0
STOPS = ((0.0, (253, 231, 37)), (0.25, (94, 201, 98)), (0.5, (33, 145, 140)), (0.75, (59, 82, 139)), (1.0, (68, 1, 84)))
MODEL_MU_RGB, NO_SLIP_RGB = (154, 154, 154), (17, 17, 17)
_POINT = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("red", "u1"), ("green", "u1"), ("blue", "u1"),
                   ("alpha", "u1")])  # fmt: skip


@dataclass(frozen=True)
class Chute:
    """What is drawn: ``world`` in ``l0``, the leg length ``l0`` [m] that makes it metres, and
    what it is in words (``world``'s metadata)."""

    world: World
    l0: float
    label: str


def chute_of(session: Session, source: Run, frames: dict | None) -> Chute:
    """The chute run ``source`` climbed — a robot run, or a simulated one (:mod:`backend.services.mcap_sim`) —
    (its body's heights ``frames["y"]`` [m], if any, for parallel walls' height)."""
    l0 = get_preset(ROBOT_PRESET).leg_length
    if source.world_id is not None:
        stored = stored_worlds.get(session, source.world_id)
        return Chute(world_from_document(stored.document, l0), l0, f"{stored.name} (world {stored.id})")
    highest = float(np.max(frames["y"])) if frames is not None and frames["y"].size else 0.0
    d_hat = float(source.model["d_hat"])
    return Chute(parallel(d_hat, max(highest / l0, 0.0) + 1.0), l0, f"parallel walls {d_hat * l0:.4g} m apart")


def messages(chute: Chute, time_ns: int) -> dict[str, list[tuple[int, object]]]:
    """:data:`CHANNELS`' one message each at ``time_ns``."""
    return {"/world/scene": [(time_ns, scene(chute, time_ns))], "/world/points": [(time_ns, points(chute, time_ns))]}


def is_foothold(mu: float) -> bool:
    """A segment with grip: any friction but 0 (NaN, the model's, has grip too)."""
    return mu != 0.0


def mu_color(mu: float) -> tuple[int, int, int]:
    """A segment's colour (0-255 RGB) by its friction: NaN the model's, ``inf`` no slip, else the scale."""
    if math.isnan(mu):
        return MODEL_MU_RGB
    if math.isinf(mu):
        return NO_SLIP_RGB
    at = min(max(mu / MU_TOP, 0.0), 1.0)
    upper = next(k for k, (stop, _) in enumerate(STOPS) if stop >= at)
    if upper == 0:
        return STOPS[0][1]
    (s0, c0), (s1, c1) = STOPS[upper - 1], STOPS[upper]
    f = (at - s0) / (s1 - s0)
    return tuple(round(a + f * (b - a)) for a, b in zip(c0, c1, strict=True))


def scene(chute: Chute, time_ns: int) -> SceneUpdate:
    """The chute's sides as ``foxglove.SceneUpdate`` entities (the module's docstring)."""
    update = SceneUpdate()
    for name in SIDES:
        side = chute.world.side(name)
        entity = update.entities.add(id=name, frame_id=FRAME, frame_locked=True)
        entity.timestamp.FromNanoseconds(time_ns)
        described = {
            "side": name,
            "world": chute.label,
            "mu": json.dumps([_mu_entry(mu) for mu in side.mu]),
            "footholds": json.dumps([k for k, mu in enumerate(side.mu) if is_foothold(mu)]),
        }
        for key, value in described.items():
            entity.metadata.add(key=key, value=value)
        metres = side.points * chute.l0
        for k, mu in enumerate(side.mu):
            entity.cubes.append(slab(name, metres[k], metres[k + 1], mu))
        line = entity.lines.add(type=LinePrimitive.LINE_STRIP, thickness=LINE_WIDTH, scale_invariant=True)
        line.pose.orientation.w = 1.0
        line.color.CopyFrom(Color(r=0.0, g=0.0, b=0.0, a=1.0))
        for x, z in metres:
            line.points.add(x=float(x), y=0.0, z=float(z))
    return update


def slab(side: str, a: np.ndarray, b: np.ndarray, mu: float) -> CubePrimitive:
    """The slab of segment ``a`` to ``b`` ([x, z] in metres) on ``side``: its local z along the
    segment, its local x across it, its face toward the chute on the segment."""
    (dx, dz), length = b - a, math.hypot(*(b - a))
    inward = np.array([dz, -dx] if side == "left" else [-dz, dx]) / length
    thickness = FOOTHOLD if is_foothold(mu) else NO_GRIP
    centre = (a + b) / 2 - inward * thickness / 2
    half = 0.5 * math.atan2(dx, dz)  # a turn about +y takes local z (0, 0, 1) to (dx, 0, dz) / length
    cube = CubePrimitive(color=_color(mu))
    cube.pose.position.x, cube.pose.position.z = float(centre[0]), float(centre[1])
    cube.pose.orientation.y, cube.pose.orientation.w = math.sin(half), math.cos(half)
    cube.size.x, cube.size.y, cube.size.z = thickness, DEPTH, length
    return cube


def points(chute: Chute, time_ns: int) -> PointCloud:
    """The chute's sides as a ``foxglove.PointCloud`` of coloured points (the module's docstring)."""
    cloud = np.concatenate([_side_points(chute.world.side(name), chute.l0) for name in SIDES])
    message = PointCloud(
        frame_id=FRAME,
        point_stride=_POINT.itemsize,
        fields=[PackedElementField(name=name, offset=_POINT.fields[name][1],
                                   type=PackedElementField.FLOAT64 if name in "xyz" else PackedElementField.UINT8)
                for name in _POINT.names],
        data=cloud.tobytes(),
    )  # fmt: skip
    message.timestamp.FromNanoseconds(time_ns)
    message.pose.position.SetInParent()  # the identity pose, written out
    message.pose.orientation.w = 1.0
    return message


def _side_points(side: Side, l0: float) -> np.ndarray:
    metres = side.points * l0
    rows = []
    for k, mu in enumerate(side.mu):
        a, b = metres[k], metres[k + 1]
        steps = max(1, math.ceil(math.hypot(*(b - a)) / (SOLID if is_foothold(mu) else DOTTED)))
        rgba = (*mu_color(mu), _byte(FOOTHOLD_ALPHA if is_foothold(mu) else NO_GRIP_ALPHA))
        rows += [(*(a + (b - a) * (j / steps)), rgba) for j in range(steps)]
    rows.append((*metres[-1], rgba))  # the side's last vertex, in its last segment's colour
    cloud = np.zeros(len(rows), _POINT)
    cloud["x"], cloud["z"] = [row[0] for row in rows], [row[1] for row in rows]
    for channel, name in enumerate(("red", "green", "blue", "alpha")):
        cloud[name] = [row[2][channel] for row in rows]
    return cloud


def _color(mu: float) -> Color:
    r, g, b = mu_color(mu)
    return Color(r=r / 255, g=g / 255, b=b / 255, a=FOOTHOLD_ALPHA if is_foothold(mu) else NO_GRIP_ALPHA)


def _byte(fraction: float) -> int:
    return round(255 * fraction)


def _mu_entry(mu: float) -> float | str | None:
    """A friction as a world file writes it: null the model's, "inf" no slip, else the number."""
    if math.isnan(mu):
        return None
    return "inf" if math.isinf(mu) else float(mu)
