"""One left/right vocabulary: walls are -1/+1, jump 0 stands on the left wall."""

import json

import numpy as np

from sim_core.model.walls import Wall, wall_of, walls_of


def test_walls_are_the_sign_of_their_x():
    assert (int(Wall.LEFT), int(Wall.RIGHT)) == (-1, 1)
    assert Wall.LEFT.other is Wall.RIGHT and Wall.RIGHT.other is Wall.LEFT
    assert -Wall.LEFT == Wall.RIGHT, "negation is the other wall, as x -> -x"
    assert Wall(-1) is Wall.LEFT and Wall.RIGHT.code == "right"
    assert json.dumps({"wall": Wall.LEFT}) == '{"wall": -1}', "stored and served as the number"


def test_jump_zero_stands_on_the_left_wall_and_they_alternate():
    assert [wall_of(k) for k in range(5)] == [Wall.LEFT, Wall.RIGHT, Wall.LEFT, Wall.RIGHT, Wall.LEFT]
    np.testing.assert_array_equal(walls_of(np.arange(5)), [int(wall_of(k)) for k in range(5)])
