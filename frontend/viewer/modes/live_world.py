"""The world a live run climbs, as live mode draws it (:mod:`frontend.viewer.modes.live`).

Read from the store once per run, through the view's services: the run's ``world_id``
(:func:`backend.services.view.stored_world`: in ``l0``, drawn at the view's robot's leg length, as
replay draws a stored run's world) and, when it follows a plan, its ``plan_job_id``'s footholds
(:func:`backend.services.view.stored_plan_footholds`). The world's sides are drawn in place of the
parallel walls, each touchdown marked where the foot met its side, and a followed plan's footholds
as simulate mode's "Follow a plan" marks them: each touchdown's target hit (green) or missed (red)
once it has passed, the next one aimed at (yellow) while the run goes on. Live mode's ghost jumps
in the world's sides (:func:`frontend.viewer.world_ghost.world_jump`). A run in no world climbs the
parallel walls.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from backend.errors import NotFound
from backend.services.view import stored_plan_footholds, stored_world
from frontend.viewer.scene import ChuteScene
from frontend.viewer.world_slabs import LEGEND
from sim_core import PhysicalParams
from sim_core.model.errors import ParameterError
from sim_core.model.walls import Wall
from sim_core.world.files import world_from_document
from sim_core.world.world import World


def foot_on_side(world: World, leg_length: float, wall: int, foot_height: float) -> float:
    """[m] the ``x`` where a foot on ``wall`` (-1 left, +1 right) at ``foot_height`` [m] meets
    ``world``'s side (``world`` in ``l0``, drawn at ``leg_length`` [m]): a live touchdown's marker,
    and a stored robot run's in replay (:mod:`frontend.viewer.recordings`)."""
    side = world.left if wall == Wall.LEFT else world.right
    return side.x_at(foot_height / leg_length) * leg_length


@dataclass(frozen=True)
class LiveWorld:
    """A live run's world as drawn: ``world`` (``l0``; None: the parallel walls) at ``leg_length``
    [m], its open frictions the model's ``mu``; ``footholds``, those of the plan it follows, one
    per touchdown of the plan's climb: side (0 left, 1 right), segment and target ``x``, ``y``
    [l0]; ``note`` says what could not be read."""

    world_id: int | None = None
    world: World | None = None
    leg_length: float = 0.0  # [m]
    model_mu: float = math.inf
    plan_job_id: int | None = None
    footholds: tuple[tuple[int, int, float, float], ...] = ()
    note: str = ""

    @classmethod
    def of(cls, run, sessions, robot: PhysicalParams) -> LiveWorld:
        """The world live run ``run`` (a run snapshot, or None) climbs, read through ``sessions``
        (None: a view without a store), drawn at ``robot``'s size."""
        world_id = None if run is None else run.world_id
        if world_id is None:
            return cls()
        if sessions is None:
            return cls(world_id, note=f"world {world_id} is not drawn: this view has no store to read it from")
        try:
            world = world_from_document(stored_world(sessions, world_id))
        except (NotFound, ParameterError) as error:
            return cls(world_id, note=f"world {world_id} is not drawn: {error}")
        footholds, note = (), ""
        if run.plan_job_id is not None:
            try:
                footholds = tuple(stored_plan_footholds(sessions, run.plan_job_id))
            except NotFound as error:
                note = f"the plan's footholds are not drawn: {error}"
        return cls(world_id, world, robot.leg_length, robot.to_model().mu, run.plan_job_id, footholds, note)

    def draw(self, scene: ChuteScene) -> None:
        """The world on ``scene``, or the parallel walls (sent once: ChuteScene.set_world)."""
        scene.set_world(self.world, self.leg_length, self.model_mu)

    def foot_x(self, touchdown) -> float | None:
        """[m] where ``touchdown``'s foot met its side, at the foot's height; None: on the parallel wall."""
        if self.world is None:
            return None
        return foot_on_side(self.world, self.leg_length, touchdown.wall, touchdown.foot_height)

    def mark(self, scene: ChuteScene, touchdown) -> None:
        """``touchdown``'s marker at its foot and, following a plan, its target: hit or missed."""
        scene.add_touchdown(touchdown.wall, touchdown.foot_height, self.foot_x(touchdown))
        row = touchdown.index + 1  # detected touchdown k is the climb's touchdown k + 1: the plan's row
        if row < len(self.footholds):
            side, segment, x, y = self.footholds[row]
            scene.add_target(x * self.leg_length, y * self.leg_length, hit=self.landed(touchdown) == (side, segment))

    def landed(self, touchdown) -> tuple[int, int]:
        """The side (0 left, 1 right) and segment ``touchdown``'s foot met, numbered as the plan
        numbers them (sim_core.world.geometry.segment_at: -1 below the first vertex, a height at a
        vertex on the segment above it)."""
        left = touchdown.wall == Wall.LEFT
        heights = (self.world.left if left else self.world.right).points[:, 1]
        return (0 if left else 1), int(np.searchsorted(heights, touchdown.foot_height / self.leg_length, "right")) - 1

    def aim(self, scene: ChuteScene, detected: int, active: bool) -> None:
        """The foothold the next touchdown (``detected`` have been) aims at while the run is ``active``."""
        row = detected + 1
        if active and row < len(self.footholds):
            _side, _segment, x, y = self.footholds[row]
            scene.show_aim(x * self.leg_length, y * self.leg_length)
        else:
            scene.show_aim(None, None)

    def words(self) -> str:
        """The readout's line of the world climbed ("" between the parallel walls)."""
        if self.world is None:
            return "" if self.note == "" else f"**World:** {self.note}  \n"
        plan = "" if self.plan_job_id is None else f" · following plan job {self.plan_job_id}"
        note = "" if self.note == "" else f" · {self.note}"
        return f"**Climbing** world {self.world_id} {self.world.name!r}{plan}{note}  \n{LEGEND}  \n"
