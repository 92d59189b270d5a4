"""The chute in viser: walls at their true distance, a height ruler, the robot, its trail.

Nodes are named as paths under ``/chute`` and created once; each frame only moves them
(``ChuteScene.show``). ``/chute`` itself slides down as the robot climbs when "follow" is on,
so the camera a person has placed keeps the robot in view. Works on any viser ``SceneApi``: the
service's live view or a private server that records a replay for export.
"""

from __future__ import annotations

import collections
import math

import numpy as np
import viser

from frontend.viewer.geometry import (
    bow_leg,
    energy_color,
    idle_foot,
    polyline_segments,
    ruler_ticks,
    to_scene,
)
from frontend.viewer.motion import STANCE, Pose
from sim_core import LegControl, PhysicalParams

WALL_THICKNESS = 0.03  # [m]
DEPTH = 0.35  # [m] how deep the walls are drawn (the model is planar)
BODY_RADIUS = 0.022  # [m]
LEG_THICKNESS = 0.012  # [m]
TRAIL_JUMPS = 30  # past jumps whose trail stays drawn
TOUCHDOWN_MARKERS = 60
HEADROOM = 1.5  # [m] walls and ruler reach this far above the highest point shown
FOLLOW_MARGIN = 0.6  # [m] with follow on, the body stays this high: where the default camera looks
WALL_COLOR = (205, 208, 214)
BODY_COLOR = (35, 45, 60)
GHOST_COLOR = (120, 200, 255)
TRAIL_COLOR = (150, 150, 170)
GHOST_TRAIL_COLOR = (80, 170, 230)
TOUCHDOWN_COLOR = (240, 150, 0)
FOOT_COLOR = (240, 150, 0)


class ChuteScene:
    """The scene's nodes and how to move them."""

    def __init__(self, scene: viser.SceneApi, robot: PhysicalParams):
        self.scene = scene
        self.robot = robot
        self.top = 0.0
        self.offset = 0.0
        scene.set_up_direction("+z")
        self.root = scene.add_frame("/chute", show_axes=False)
        half = 0.5 * robot.wall_distance
        self.walls = [
            scene.add_box(
                f"/chute/wall_{name}",
                color=WALL_COLOR,
                dimensions=(WALL_THICKNESS, DEPTH, 1.0),
                position=(side * (half + 0.5 * WALL_THICKNESS), 0.0, 0.5),
            )
            for name, side in (("left", -1), ("right", 1))
        ]
        scene.add_box(
            "/chute/floor",
            color=(170, 170, 175),
            dimensions=(robot.wall_distance + 2 * WALL_THICKNESS, DEPTH, 0.01),
            position=(0.0, 0.0, -0.005),
        )
        self.ruler = scene.add_line_segments(
            "/chute/ruler", points=np.zeros((1, 2, 3)), colors=(60, 60, 60), thickness=0.002
        )
        self.ruler_labels: list = []
        self.body = scene.add_icosphere("/chute/body", radius=BODY_RADIUS, color=BODY_COLOR)
        # The legs hang from the body (drawn relative to it): a client that repaints slowly moves
        # them with the body at once, even while it is still rebuilding their shape.
        self.legs = {
            wall: scene.add_line_segments(
                f"/chute/body/leg_{name}", points=np.zeros((1, 2, 3)), colors=(0, 0, 0), thickness=LEG_THICKNESS
            )
            for name, wall in (("left", -1), ("right", 1))
        }
        self.foot = scene.add_icosphere("/chute/foot", radius=0.012, color=FOOT_COLOR, visible=False)
        self.trail = scene.add_line_segments(
            "/chute/trail/current", points=np.zeros((1, 2, 3)), colors=TRAIL_COLOR, thickness=0.003
        )
        self.ghost = scene.add_icosphere(
            "/chute/ghost/body", radius=BODY_RADIUS, color=GHOST_COLOR, opacity=0.45, visible=False
        )
        self.ghost_trail = scene.add_line_segments(
            "/chute/ghost/trail", points=np.zeros((1, 2, 3)), colors=GHOST_TRAIL_COLOR, thickness=0.003, visible=False
        )
        self.past_trails: collections.deque = collections.deque()
        self.touchdowns: collections.deque = collections.deque()
        self._trail_count = 0
        self._marker_count = 0
        self.reach(1.0)

    # Static parts -------------------------------------------------------------------------------
    def reach(self, height: float) -> None:
        """Make the walls and the ruler reach ``height`` [m] plus headroom (grows, never shrinks)."""
        top = math.ceil((max(height, 0.0) + HEADROOM) * 2.0) / 2.0
        if top <= self.top:
            return
        self.top = top
        for wall in self.walls:
            x = wall.position[0]
            wall.dimensions = (WALL_THICKNESS, DEPTH, top)
            wall.position = (x, 0.0, 0.5 * top)
        ticks, majors = ruler_ticks(top)
        inner = -0.5 * self.robot.wall_distance
        length = np.where(np.isin(ticks, majors), 0.04, 0.02)
        front = -0.5 * DEPTH
        starts = np.column_stack([np.full(ticks.size, inner), np.full(ticks.size, front), ticks])
        ends = starts + np.column_stack([length, np.zeros(ticks.size), np.zeros(ticks.size)])
        spine = np.array([[[inner, front, 0.0], [inner, front, top]]])
        self.ruler.points = np.concatenate([spine, np.stack([starts, ends], axis=1)])
        for i, height_mark in enumerate(majors[len(self.ruler_labels) :], start=len(self.ruler_labels)):
            self.ruler_labels.append(
                self.scene.add_label(
                    f"/chute/ruler/label_{i}",
                    f"{height_mark:.2f} m",
                    position=(inner + 0.045, front, height_mark),
                    font_screen_scale=0.7,
                    anchor="center-left",
                )
            )

    # Per frame ----------------------------------------------------------------------------------
    def show(self, pose: Pose, idle_leg: LegControl | None, trail: np.ndarray, *, follow: bool) -> None:
        """Move the robot to ``pose``; ``idle_leg`` is the controls of the leg not drawn by the pose
        (None: legs unknown, as for tracker data); ``trail`` (n, 2) the body's path this jump."""
        robot = self.robot
        body = (pose.x, pose.y)
        self.body.position = tuple(to_scene(*body))
        legs_known = math.isfinite(pose.zeta)
        if legs_known:
            foot = (pose.foot_x, pose.foot_y)
            self._draw_leg(pose.leg_wall, body, foot, pose.zeta)
            if idle_leg is not None:
                idle = idle_foot(body, idle_leg, -pose.leg_wall, robot)
                self._draw_leg(-pose.leg_wall, body, idle, idle_leg.zeta0 * robot.leg_length)
            self.foot.position = tuple(to_scene(*foot))
        for wall, leg in self.legs.items():
            leg.visible = legs_known and (wall == pose.leg_wall or idle_leg is not None)
        self.foot.visible = legs_known and pose.phase == STANCE
        if len(trail) >= 2:
            self.trail.points = polyline_segments(trail)
        self.reach(pose.y)
        if follow:
            self.offset = max(pose.y - FOLLOW_MARGIN, 0.0)
        self.root.position = (0.0, 0.0, -self.offset)

    def show_ghost(self, pose: Pose | None, trail: np.ndarray | None = None) -> None:
        """The model's prediction beside the robot (live) or a second run (replay); None hides it."""
        self.ghost.visible = pose is not None
        self.ghost_trail.visible = trail is not None and len(trail) >= 2
        if pose is not None:
            self.ghost.position = tuple(to_scene(pose.x, pose.y))
        if trail is not None and len(trail) >= 2:
            self.ghost_trail.points = polyline_segments(trail)

    def _draw_leg(self, wall: int, hip, foot, zeta: float) -> None:
        leg = self.legs[wall]
        reach = (foot[0] - hip[0], foot[1] - hip[1])
        segments = polyline_segments(bow_leg((0.0, 0.0), reach, self.robot.leg_length))
        leg.points = segments
        leg.colors = np.broadcast_to(np.array(energy_color(zeta, self.robot), dtype=np.uint8), segments.shape).copy()

    # Jump history -------------------------------------------------------------------------------
    def add_jump_trail(self, points: np.ndarray) -> None:
        """Keep a finished jump's path drawn (the last TRAIL_JUMPS of them)."""
        if len(points) < 2:
            return
        self._trail_count += 1
        self.past_trails.append(
            self.scene.add_line_segments(
                f"/chute/trail/jump_{self._trail_count}",
                points=polyline_segments(points),
                colors=TRAIL_COLOR,
                thickness=0.002,
            )
        )
        while len(self.past_trails) > TRAIL_JUMPS:
            self.past_trails.popleft().remove()

    def add_touchdown(self, wall: int, foot_height: float) -> None:
        """Mark where a foot met ``wall`` (-1 left, +1 right) at ``foot_height`` [m]."""
        x = wall * 0.5 * self.robot.wall_distance
        self._marker_count += 1
        self.touchdowns.append(
            self.scene.add_box(
                f"/chute/touchdowns/{self._marker_count}",
                color=TOUCHDOWN_COLOR,
                dimensions=(0.006, 0.06, 0.012),
                position=(x, 0.0, foot_height),
            )
        )
        while len(self.touchdowns) > TOUCHDOWN_MARKERS:
            self.touchdowns.popleft().remove()

    def clear_history(self) -> None:
        """Remove trails and touchdown markers (a reset or a new run)."""
        for handle in (*self.past_trails, *self.touchdowns):
            handle.remove()
        self.past_trails.clear()
        self.touchdowns.clear()
        self.trail.points = np.zeros((1, 2, 3))
        self.offset = 0.0
        self.root.position = (0.0, 0.0, 0.0)
