"""What a stored run's replay shows at an instant, drawn on a :class:`ChuteScene`: the one
definition of a replay frame, which replay mode draws live and the shared file
(:mod:`frontend.viewer.share`) is held equal to (tests/frontend/viewer/test_share.py)."""

from __future__ import annotations

from frontend.viewer.recordings import Recording
from frontend.viewer.scene import ChuteScene


def show_frame(
    scene: ChuteScene, recording: Recording, overlay: Recording | None, t: float, marked: tuple[int, int]
) -> tuple[int, int]:
    """Draw ``recording`` at time ``t`` (and ``overlay`` as the ghost). ``marked``: the touchdowns
    of each drawn so far (their markers and finished jumps' trails); returns them at ``t``.

    The shared file (:mod:`frontend.viewer.share`) writes the same scene frame by frame from the
    recording's arrays: what a frame shows is defined by :class:`Recording`'s ``touchdowns_until``,
    ``trail`` and ``jump_trail`` for both."""
    shown, ghost_shown = marked
    scene.set_world(recording.world, recording.robot.leg_length, recording.world_mu)  # sent once
    now = int(recording.touchdowns_until(t))
    for k in range(shown, now):
        scene.add_touchdown(*recording.touchdown_marker(k))
        if k > 0:
            scene.add_jump_trail(recording.jump_trail(k))
    pose = recording.clip.pose_at(t)
    scene.show(pose, recording.idle_leg(pose.leg_wall), recording.trail(t), follow=True)
    if overlay is None:
        scene.show_ghost(None)
        return now, 0
    ghost_now = int(overlay.touchdowns_until(t))
    for k in range(max(ghost_shown, 1), ghost_now):
        scene.add_ghost_jump_trail(overlay.jump_trail(k))
    scene.show_ghost(overlay.clip.pose_at(t), overlay.trail(t))
    return now, ghost_now
