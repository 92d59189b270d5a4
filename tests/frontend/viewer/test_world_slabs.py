"""A world's sides as slabs (frontend/viewer/world_slabs.py): each along its segment, at its
inclination, its inner face on the segment, coloured by friction; and drawn on a scene in place
of the parallel walls."""

import math

import numpy as np
import pytest

from frontend.viewer.scene import ChuteScene
from frontend.viewer.world_slabs import (
    ABOVE_TOP,
    NO_GRIP,
    NO_SLIP,
    SLAB_THICKNESS,
    friction_color,
    world_slabs,
    world_words,
)
from sim_core import get_preset
from sim_core.world.world import Side, World, parallel

L0 = 0.2  # [m]
WORLD = World(
    Side(np.array([[-0.5, 0.2], [-0.5, 1.0], [-1.5, 2.0]]), np.array([0.0, math.inf])),
    Side(np.array([[0.5, 0.0], [0.5, 2.0]]), np.array([0.8])),
    "known",
)


def _rotate(wxyz, vector):
    w, x, y, z = wxyz
    q = np.array([x, y, z])
    v = np.asarray(vector, dtype=float)
    return v + 2.0 * np.cross(q, np.cross(q, v) + w * v)


def test_slabs_lie_along_their_segments_outside_the_chute():
    slabs = {slab.name: slab for slab in world_slabs(WORLD, L0, 1.2)}
    assert list(slabs) == ["left_below", "left_0", "left_1", "left_above", "right_0", "right_above"]
    ramp = slabs["left_1"]  # from (-0.1, 0.2) m to (-0.3, 0.4) m: leaning out at 45°
    assert ramp.dimensions == pytest.approx((SLAB_THICKNESS, 0.35, math.sqrt(2) * 0.2))
    along = _rotate(ramp.wxyz, (0.0, 0.0, 1.0))
    np.testing.assert_allclose(along, np.array([-1.0, 0.0, 1.0]) / math.sqrt(2), atol=1e-12)
    inward = _rotate(ramp.wxyz, (1.0, 0.0, 0.0))  # the box's thickness axis: normal to the segment
    assert abs(np.dot(inward, along)) < 1e-12
    outward = np.array([-1.0, 0.0, -1.0]) / math.sqrt(2)  # away from the chute, under the ramp
    face = np.array(ramp.position) - 0.5 * SLAB_THICKNESS * outward
    np.testing.assert_allclose(face, (-0.2, 0.0, 0.3), atol=1e-12)  # the segment's midpoint
    wall = slabs["right_0"]  # vertical: no turn, the box beside the segment
    np.testing.assert_allclose(wall.wxyz, (1.0, 0.0, 0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(wall.position, (0.1 + 0.5 * SLAB_THICKNESS, 0.0, 0.2), atol=1e-12)
    below, above = slabs["left_below"], slabs["left_above"]
    assert below.position[2] == pytest.approx(0.02) and below.dimensions[2] == pytest.approx(0.04)
    assert above.position[2] == pytest.approx(0.4 + 0.5 * ABOVE_TOP)


def test_footholds_are_coloured_by_friction():
    slabs = {slab.name: slab for slab in world_slabs(WORLD, L0, 1.2)}
    assert slabs["left_0"].color == NO_GRIP and not slabs["left_0"].foothold
    assert slabs["left_1"].color == NO_SLIP and slabs["left_1"].foothold
    assert slabs["right_0"].foothold and slabs["right_0"].color == friction_color(0.8)
    assert friction_color(0.1) != friction_color(1.0) and friction_color(1.5) == friction_color(9.0)
    assert math.isnan(slabs["left_above"].mu) and not slabs["left_above"].foothold


def test_a_scene_draws_a_world_in_place_of_the_walls_once(server):
    scene = ChuteScene(server.scene, get_preset("paper"))
    scene.set_world(WORLD, L0, 1.2)
    nodes = scene._world_nodes
    assert len(nodes) == 6 and not any(wall.visible for wall in scene.walls)
    scene.set_world(WORLD, L0, 1.2)
    assert scene._world_nodes is nodes, "the same world again: nothing sent"
    assert scene.chute_words == "world 'known', sides 0.20 m to 0.40 m apart", "the header's words"
    half = 0.5 * scene.robot.wall_distance
    assert scene._ruler.position == pytest.approx((-0.1 + half, 0.0, 0.0)), "the ruler on the left side's floor"
    scene.set_world(parallel(2.0), L0, 1.2)
    assert len(scene._world_nodes) == 4
    scene.set_world(None)
    assert scene._world_nodes == [] and all(wall.visible for wall in scene.walls)
    assert scene.chute_words == "walls 0.54 m apart" and scene._ruler.position == pytest.approx((0.0, 0.0, 0.0))
    scene.add_touchdown(-1, 0.3, -0.25)
    assert scene.touchdown_markers.nodes[0].position == pytest.approx((-0.25, 0.0, 0.3))


def test_a_world_is_said_by_its_name_and_how_far_apart_its_sides_are():
    assert world_words(WORLD, L0) == "world 'known', sides 0.20 m to 0.40 m apart", "narrowest to widest"
    assert world_words(parallel(2.0), L0) == "world 'parallel', sides 0.40 m apart"
    unnamed = World(WORLD.left, WORLD.right)
    assert world_words(unnamed, 0.1) == "an unnamed world, sides 0.10 m to 0.20 m apart"
