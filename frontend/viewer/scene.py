"""The chute in viser: walls at their true distance, a height ruler, the robot, its trail.

Nodes are named as paths under ``/chute`` and created once; each frame only moves them
(``ChuteScene.show``). ``/chute`` itself slides down as the robot climbs when "follow" is on,
so the camera a person has placed keeps the robot in view. Works on any viser ``SceneApi``: the
service's live view or a private server that records a replay for export. Touchdown markers and
trails are rings of reused nodes (:mod:`frontend.viewer.node_rings`).
"""

from __future__ import annotations

import math

import numpy as np
import viser

from frontend.viewer.geometry import bow_leg, energy_color, idle_foot, polyline_segments, to_scene
from frontend.viewer.motion import Pose
from frontend.viewer.node_rings import NodeRing, StreamedTrail, hidden_lines
from frontend.viewer.ruler import Growth, grown
from frontend.viewer.world_slabs import world_slabs, world_width, world_words
from sim_core import LegControl, PhysicalParams
from sim_core.model.trajectory import STANCE
from sim_core.world.world import World

WALL_THICKNESS = 0.03  # [m]
DEPTH = 0.35  # [m] how deep the walls are drawn (the model is planar)
BODY_RADIUS = 0.022  # [m]
LEG_THICKNESS = 0.012  # [m]
TRAIL_JUMPS = 30  # past jumps whose trail stays drawn
# Live mode's trails are streamed (StreamedTrail): pieces of node_rings.PIECE_POINTS points, each sent once.
LIVE_TRAIL_PIECES = 40  # finished pieces of the robot's path kept: 960 tracker frames, 9.6 s at 100 Hz
GHOST_TRAIL_PIECES = 16  # finished pieces of the live ghost's jump kept: 1.1 s of the model's path
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
RULER_COLOR = (60, 60, 60)
TARGET_HIT, TARGET_MISSED, AIM_COLOR = (40, 200, 70), (220, 40, 40), (250, 215, 0)  # a followed plan's footholds
CAMERA_POSITION = (0.0, -1.25, 0.6)  # [m] level with the robot, in front of the chute
CAMERA_LOOK_AT = (0.0, 0.0, 0.6)


def place_camera(server: viser.ViserServer) -> None:
    """Where a browser's camera starts: in front of the chute, level with the followed robot."""
    server.initial_camera.position = CAMERA_POSITION
    server.initial_camera.look_at = CAMERA_LOOK_AT
    server.initial_camera.up = (0.0, 0.0, 1.0)


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
        self.floor = scene.add_box(
            "/chute/floor",
            color=(170, 170, 175),
            dimensions=(robot.wall_distance + 2 * WALL_THICKNESS, DEPTH, 0.01),
            position=(0.0, 0.0, -0.005),
        )
        self.world: World | None = None  # None: the parallel walls (set_world)
        self._world_key: tuple | None = None
        self._world_nodes: list = []
        self._wall_x = [side * (half + 0.5 * WALL_THICKNESS) for side in (-1, 1)]
        self._ruler_sections = 0  # the ruler grows in sections: "/chute/ruler", then "/chute/ruler/part_k"
        self._ruler_labels = 0
        self._ruler_x, self._ruler = -half, None  # [m] on the left wall's face; its first section (moves it all)
        self._walls_words = f"walls {robot.wall_distance:.2f} m apart"
        self.chute_words = self._walls_words  # what the view's header says of the chute (set_world)
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
        self.touchdown_markers = NodeRing(
            "/chute/touchdowns/",
            TOUCHDOWN_MARKERS,
            lambda name: scene.add_box(
                name, color=TOUCHDOWN_COLOR, dimensions=(0.006, 0.06, 0.012), position=(0.0, 0.0, 0.0), visible=False
            ),
        )
        self.jump_trails = NodeRing("/chute/trail/jump_", TRAIL_JUMPS, hidden_lines(scene, TRAIL_COLOR, 0.002))
        self.ghost_jump_trails = NodeRing(
            "/chute/ghost/jump_", TRAIL_JUMPS, hidden_lines(scene, GHOST_TRAIL_COLOR, 0.003)
        )
        self.targets = NodeRing("/chute/targets/", TOUCHDOWN_MARKERS, lambda name: scene.add_icosphere(
            name, radius=0.014, color=TARGET_HIT, position=(0.0, 0.0, 0.0), visible=False))  # fmt: skip
        self.aim, self._aim_at = None, None  # the next target, made when first shown
        # Live mode's: its nodes are made when first drawn (none in simulate, replay or a shared file).
        self.live_trail = StreamedTrail(scene, "/chute/trail/live/", LIVE_TRAIL_PIECES, TRAIL_COLOR, 0.003)
        self.live_ghost_trail = StreamedTrail(scene, "/chute/ghost/live/", GHOST_TRAIL_PIECES, GHOST_TRAIL_COLOR, 0.003)
        self.reach(1.0)

    # Static parts -------------------------------------------------------------------------------
    def growth(self, height: float) -> Growth | None:
        """What the walls and the ruler gain to reach ``height`` [m] plus headroom; None when they
        reach that high already (they grow, never shrink)."""
        top = float(self.top_for(height))
        if top <= self.top:
            return None
        return grown(self.top, top, sections=self._ruler_sections, labels=self._ruler_labels,
                     spine=(self._ruler_x, -0.5 * DEPTH), wall_size=(WALL_THICKNESS, DEPTH),
                     wall_x=self._wall_x)  # fmt: skip

    def set_world(self, world: World | None, leg_length: float = 0.0, model_mu: float = math.inf) -> None:
        """Draw ``world`` (``l0`` units, at ``leg_length`` [m], its open frictions ``model_mu``) in
        place of the parallel walls: its sides as slabs (:mod:`frontend.viewer.world_slabs`) under
        ``/chute/world/``, sent once, the ruler on its left side at the floor and the header's words
        its own (:attr:`chute_words`); None: the parallel walls again. The same world again sends nothing."""
        key = None if world is None else (id(world), leg_length, model_mu)
        if key == self._world_key:
            return
        for node in self._world_nodes:
            node.remove()
        self._world_nodes, self.world, self._world_key = [], world, key
        for wall in self.walls:
            wall.visible = world is None
        if world is None:
            self.floor.dimensions = (self.robot.wall_distance + 2 * WALL_THICKNESS, DEPTH, 0.01)
            self.floor.position = (0.0, 0.0, -0.005)
            self._ruler.position, self.chute_words = (0.0, 0.0, 0.0), self._walls_words
            return
        left, right = world_width(world, leg_length)
        self._ruler.position, self.chute_words = (left - self._ruler_x, 0.0, 0.0), world_words(world, leg_length)
        self.floor.dimensions = (right - left + 2 * WALL_THICKNESS, DEPTH, 0.01)
        self.floor.position = (0.5 * (left + right), 0.0, -0.005)
        for slab in world_slabs(world, leg_length, model_mu):
            name, options = f"/chute/world/{slab.name}", {"position": slab.position, "wxyz": slab.wxyz}
            self._world_nodes.append(self.scene.add_box(name, color=slab.color, dimensions=slab.dimensions, **options))

    @staticmethod
    def top_for(height):
        """[m] how high the walls reach for the robot at ``height`` [m] (a float or an array)."""
        return np.ceil((np.maximum(height, 0.0) + HEADROOM) * 2.0) / 2.0

    def reach(self, height: float) -> None:
        """Make the walls and the ruler reach ``height`` [m] plus headroom (grows, never shrinks)."""
        growth = self.growth(height)
        if growth is None:
            return
        for wall, position in zip(self.walls, growth.wall_positions, strict=True):
            wall.dimensions = growth.wall_dimensions
            wall.position = position
        section = self.scene.add_line_segments(growth.section, points=growth.segments, colors=RULER_COLOR,
                                               thickness=0.002)  # fmt: skip
        if self._ruler is None:
            self._ruler = section  # the first section: the others hang from it
        for name, text, position in growth.labels:
            self.scene.add_label(name, text, position=position, font_screen_scale=0.7, anchor="center-left")
        self.grew(growth)

    def grew(self, growth: Growth) -> None:
        """``growth`` is drawn (by :meth:`reach`, or written straight into a recording)."""
        self.top = growth.top
        self._ruler_sections += 1
        self._ruler_labels += len(growth.labels)

    # Per frame ----------------------------------------------------------------------------------
    def show(self, pose: Pose, idle_leg: LegControl | None, trail: np.ndarray | None, *, follow: bool) -> None:
        """Move the robot to ``pose``; ``idle_leg`` is the controls of the leg not drawn by the pose
        (None: legs unknown, as for tracker data); ``trail`` (n, 2) the body's path this jump (None:
        drawn otherwise, as live mode streams it into :attr:`live_trail`)."""
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
        if trail is not None and len(trail) >= 2:
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
        if len(points) >= 2:
            self.jump_trails.show_next(points=polyline_segments(points))

    def add_ghost_jump_trail(self, points: np.ndarray) -> None:
        """Keep a finished jump of the ghost's path drawn (the last TRAIL_JUMPS of them)."""
        if len(points) >= 2:
            self.ghost_jump_trails.show_next(points=polyline_segments(points))

    def add_touchdown(self, wall: int, foot_height: float, foot_x: float | None = None) -> None:
        """Mark where a foot met ``wall`` (-1 left, +1 right) at ``foot_height`` [m] (and
        ``foot_x`` [m]: in a world; None: on the parallel wall)."""
        self.touchdown_markers.show_next(position=self.touchdown_position(wall, foot_height, foot_x))

    def touchdown_position(self, wall: int, foot_height: float, foot_x: float | None = None):
        x = wall * 0.5 * self.robot.wall_distance if foot_x is None else foot_x
        return (x, 0.0, foot_height)

    def add_target(self, x: float, y: float, *, hit: bool) -> None:
        """Mark a followed plan's foothold at ``(x, y)`` [m] once its touchdown has passed: hit or missed."""
        self.targets.show_next(position=(x, -0.04, y), color=TARGET_HIT if hit else TARGET_MISSED)

    def show_aim(self, x: float | None, y: float | None) -> None:
        """The foothold the coming touchdown aims at (None: none); sent only when it moves."""
        at = None if x is None else (float(x), -0.04, float(y))
        if at == self._aim_at:
            return
        if self.aim is None:
            self.aim = self.scene.add_icosphere("/chute/aim", radius=0.018, color=AIM_COLOR, visible=False)
        if at is not None:
            self.aim.position = at
        self.aim.visible, self._aim_at = at is not None, at

    def clear_history(self) -> None:
        """Hide trails and touchdown markers (a reset or a new run)."""
        for ring in (self.touchdown_markers, self.jump_trails, self.ghost_jump_trails, self.targets):
            ring.clear()
        self.show_aim(None, None)
        self.live_trail.clear()
        self.live_ghost_trail.clear()
        self.trail.points = np.zeros((1, 2, 3))
        self.offset = 0.0
        self.root.position = (0.0, 0.0, 0.0)
