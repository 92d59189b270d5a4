"""Live mode (frontend/viewer/modes/live.py): the robot as everyone who chooses it sees it, the
model's ghost beside it (the paper's or a calibration), and its trail: bounded, sent a piece at a
time (``StreamedTrail``, tested on its own in tests/frontend/viewer/test_node_rings.py), and drawn
afresh at each run's start.

The first tests run the service with a virtual robot and headless browsers (conftest.py).

:class:`LiveMode` draws frame by frame (60 a second) on a private viser server's scene while its
tracker is fed as the virtual robot feeds it: 100 frames a second, the clock starting again at
each run. What the browser gets is what viser's serializer records, decoded as the browser
decodes it (tests/frontend/viewer/test_share.py); byte counts are of the arrays sent.
"""

from __future__ import annotations

import dataclasses
import threading
import time
from dataclasses import dataclass

import numpy as np
import viser

from backend.robot.live_run import RunSnapshot
from backend.robot.touchdown import Touchdown
from backend.robot.tracker import Calibration, Pose, PoseHistory
from frontend.viewer.geometry import polyline_segments
from frontend.viewer.modes.live import LiveMode
from frontend.viewer.node_rings import PIECE_POINTS
from frontend.viewer.scene import LIVE_TRAIL_PIECES, ChuteScene
from sim_core import get_preset
from sim_core.model.walls import Wall
from tests.frontend.viewer.test_share import SceneTree, decode_recording
from tests.frontend.viewer.view_service import wait_for

ROBOT = get_preset("paper")
TRACKER_RATE = 100.0  # [Hz] the virtual robot's tracker frames
FRAME_RATE = 60.0  # [Hz] the view's frames
SEGMENT_BYTES = 2 * 3 * 4  # a segment's two points, float32
# A frame sends at most the piece under way and one finished piece.
FRAME_TRAIL_BYTES = 2 * (PIECE_POINTS - 1) * SEGMENT_BYTES
TRAIL_SEGMENTS = LIVE_TRAIL_PIECES * (PIECE_POINTS - 1)  # a full trail: its finished pieces


def climb(t: np.ndarray, start_height: float) -> np.ndarray:
    """[m] a body zigzagging between the walls as it climbs, (n, 2)."""
    return np.column_stack([0.1 * np.sin(2 * np.pi * t), start_height + 0.05 * t])


@dataclass
class Robot:
    """The robot service as live mode reads it: its tracker and its latest run."""

    tracker: PoseHistory
    run: RunSnapshot | None = None

    def run_snapshot(self) -> RunSnapshot | None:
        return self.run


class Live:
    """Live mode on a viser server's scene, recorded frame by frame; ``sessions``: its store (None: none)."""

    def __init__(self, server: viser.ViserServer, sessions=None):
        self.robot = Robot(PoseHistory(Calibration()))
        self.mode = LiveMode(server, ChuteScene(server.scene, ROBOT), threading.RLock(), self.robot, sessions)
        self.serializer = server.get_scene_serializer()
        self.frames = 0  # frames drawn so far
        self.ends: list[int] = []  # frames drawn by the end of each run
        self.frame()  # the robot connected, no run yet: the view is watching when the first starts

    def frame(self) -> None:
        self.mode.frame(1 / FRAME_RATE)
        self.serializer.insert_sleep(1 / FRAME_RATE)
        self.frames += 1

    def run(self, seconds: float, start_height: float, **fields) -> np.ndarray:
        """A run of ``seconds``: its poses (n, 2) [m], fed at the tracker's rate while drawing;
        ``fields``: more of its snapshot's (``world_id``, say)."""
        first = self.robot.tracker.count()
        self.robot.run = RunSnapshot(
            run_id=len(self.ends) + 1, started=time.time(), jumps=100, max_seconds=60.0, first_pose=first, **fields
        )
        times = np.arange(0.0, seconds, 1 / TRACKER_RATE)  # the robot's clock: from 0 each run
        path = climb(times, start_height)
        fed = 0
        for k in range(int(seconds * FRAME_RATE)):
            while fed < times.size and times[fed] <= k / FRAME_RATE:
                self.robot.tracker.add(Pose(float(times[fed]), *map(float, path[fed])))
                fed += 1
            self.frame()
        self.ends.append(self.frames)
        return path[:fed]

    def recorded(self) -> list[tuple[SceneTree, int]]:
        """After each frame: the browser's scene, and the bytes of trail arrays the frame sent."""
        messages = decode_recording(self.serializer.serialize())["messages"]
        tree, out, i = SceneTree(), [], 0
        for frame in range(self.frames):
            sent = 0
            while i < len(messages) and messages[i][0] <= (frame + 0.5) / FRAME_RATE:
                message = messages[i][1]
                tree.apply(message)
                if message.get("name", "").startswith("/chute/trail"):
                    sent += _array_bytes(message)
                i += 1
            out.append((_copy(tree), sent))
        return out


def _array_bytes(value) -> int:
    if isinstance(value, np.ndarray):
        return value.nbytes
    if isinstance(value, dict):
        return sum(_array_bytes(item) for item in value.values())
    return 0


def _copy(tree: SceneTree) -> dict:
    return {name: dict(node, props=dict(node["props"])) for name, node in tree.shown().items()}


def trail_drawn(scene: dict) -> set[bytes]:
    """The segments the trail nodes draw (those of some length), each as its float32 bytes."""
    segments = [
        node["props"]["points"].reshape(-1, 2, 3)
        for name, node in scene.items()
        if name.startswith("/chute/trail/") and node["kind"] == "LineSegmentsMessage"
    ]
    drawn = np.concatenate(segments) if segments else np.zeros((0, 2, 3), np.float32)
    return {segment.tobytes() for segment in drawn if np.any(segment[0] != segment[1])}


def segments_of(path: np.ndarray) -> set[bytes]:
    return {segment.tobytes() for segment in polyline_segments(path).astype(np.float32)}


def test_live_mode_shows_the_robot_to_everyone_who_chooses_it_with_the_model_beside_it(service, browsers, virtual):
    client, auth, _view = service
    robot, port = virtual
    (_, watching), (_, also), (_, simulating) = browsers(), browsers(), browsers()
    try:
        answer = client.post("/api/v1/robot/connect", json={"url": robot.url, "tracker_port": port}, headers=auth)
        assert answer.status_code == 200, answer.text
        watching.set_mode("live")
        also.set_mode("live")
        live = watching.modes["live"]
        controls = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]
        assert (
            client.post("/api/v1/robot/runs", json={"controls": controls, "jumps": 6}, headers=auth).status_code == 202
        )
        wait_for(lambda: not client.get("/api/v1/robot").json()["run"]["active"], timeout=30)
        # A loaded machine's control loop may see a touchdown or more past the sixth before it ends the
        # run: the views show what the run recorded, however many that was.
        recorded = client.get("/api/v1/robot").json()["run"]["touchdowns"]
        assert recorded >= 6
        wait_for(lambda: live._marked == recorded and also.modes["live"]._marked == recorded)
        assert watching.scene.ghost.visible, "the model's jump from the last touchdown is drawn"
        ghost_trail = watching.scene.live_ghost_trail
        assert ghost_trail.finished.count or len(ghost_trail.piece) >= 2, "and its trail since the touchdown"
        assert simulating.mode.name == "simulate" and simulating.modes["live"]._marked == 0, "choosing is each one's"
        # Without noise the robot is the model: the ghost lands where the robot touched down.
        assert abs(live.last_error) < 0.01, f"model's touchdown height error {live.last_error:+.4f} m"
        assert f"Touchdowns this run:** {recorded} " in live.readout(60.0)
    finally:
        client.post("/api/v1/robot/disconnect", headers=auth)


def test_the_live_ghost_can_predict_with_a_calibrated_model(service, browsers):
    """A robot unlike the paper's: the ghost of a calibration of it lands where the robot touches
    down, the paper's does not; each browser chooses its own."""
    import socket

    from backend.robot.virtual import VirtualRobot
    from backend.store.models import ModelPreset
    from sim_core.model.noise import NO_NOISE
    from tests.helpers import free_port
    from tests.tracked_climbs import Truth

    client, auth, _view = service
    truth = Truth.of(alpha=72.0, c_zeta=1.25, c_psi=0.8, psi0_offset_deg=(0.6, -0.8), zeta0_offset=(0.004, -0.005))
    with client.app.state.sessions() as session:
        session.add(ModelPreset(name="truth", base="paper", physical=dataclasses.asdict(truth.robot),
                                offsets=truth.offsets.to_dict(), fit={}, runs=[], code_version="test"))  # fmt: skip
        session.commit()
    port = free_port(socket.SOCK_DGRAM)
    robot = VirtualRobot(tracker_to=("127.0.0.1", port), robot=truth.robot, leg_offsets=truth.offsets,
                         noise=NO_NOISE, tracker_noise=0.0, drop_rate=0.0, speed=4.0).start()  # fmt: skip
    (_, paper_view), (_, calibrated_view) = browsers(), browsers()
    try:
        answer = client.post("/api/v1/robot/connect", json={"url": robot.url, "tracker_port": port}, headers=auth)
        assert answer.status_code == 200, answer.text
        paper, calibrated = paper_view.modes["live"], calibrated_view.modes["live"]
        assert calibrated.gui_ghost_model.options == ("paper", "truth")
        calibrated.use_ghost_model("truth")
        paper_view.set_mode("live")
        calibrated_view.set_mode("live")
        controls = [{"psi0_deg": 30, "zeta0": 0.87}, {"psi0_deg": 30, "zeta0": 0.9}]
        assert (
            client.post("/api/v1/robot/runs", json={"controls": controls, "jumps": 6}, headers=auth).status_code == 202
        )
        wait_for(lambda: not client.get("/api/v1/robot").json()["run"]["active"], timeout=30)
        run = client.get("/api/v1/robot").json()["run"]
        recorded = run["touchdowns"]
        assert recorded >= 6, f"the run ended after {recorded} touchdowns: {run.get('end_reason')!r}"
        # The views draw what the run recorded; a loaded machine's views may be a few frames behind.
        wait_for(lambda: paper._marked == recorded and calibrated._marked == recorded, timeout=30)
        assert abs(calibrated.last_error) < 0.002, f"the calibrated ghost's error {calibrated.last_error:+.4f} m"
        assert abs(paper.last_error) > 3 * abs(calibrated.last_error), (paper.last_error, calibrated.last_error)
    finally:
        client.post("/api/v1/robot/disconnect", headers=auth)
        robot.stop()


def test_the_live_trail_is_bounded_sent_a_piece_at_a_time_and_afresh_at_each_run(server):
    live = Live(server)
    first = live.run(30.0, start_height=0.1)  # 3000 tracker frames: more than the trail keeps
    second = live.run(2.0, start_height=0.12)  # the robot back near the floor, its clock from 0
    frames = live.recorded()

    sent = [trail_bytes for _scene, trail_bytes in frames]
    assert max(sent) <= FRAME_TRAIL_BYTES, f"a frame sent {max(sent)} B of trail: the trail is sent whole"

    end_of_first, _ = frames[live.ends[0] - 1]
    shown = trail_drawn(end_of_first)
    assert shown == segments_of(first[-(len(shown) + 1) :]), "the trail is the robot's latest path, unbroken"
    assert TRAIL_SEGMENTS <= len(shown) < TRAIL_SEGMENTS + PIECE_POINTS, "it keeps its bound: 9.6 s at 100 Hz"

    run_one = segments_of(first)
    for k in range(live.ends[0], live.ends[1]):
        scene, _ = frames[k]
        assert not trail_drawn(scene) & run_one, f"frame {k - live.ends[0]} of the second run draws the first's"
    end_of_second, _ = frames[-1]
    assert trail_drawn(end_of_second) == segments_of(second), "the second run's path from its start"


def test_choosing_live_again_draws_the_runs_trail_and_markers_again(server):
    live = Live(server)
    path = live.run(3.0, start_height=0.1)
    touchdowns = tuple(
        Touchdown(k, 0.5 * (k + 1), wall, (-0.8, -0.15), float(path[50 * (k + 1), 1]), 0.1, 20)
        for k, wall in enumerate((Wall.LEFT, Wall.RIGHT, Wall.LEFT))
    )
    live.robot.run = dataclasses.replace(live.robot.run, touchdowns=touchdowns)
    live.frame()
    live.mode.scene.clear_history()  # as choosing another mode does (ViewerSession.set_mode)
    live.mode.activate()
    live.frame()
    scene, _ = live.recorded()[-1]
    assert trail_drawn(scene) == segments_of(path), "the run's 3 s of frames, drawn again"
    markers = [node["position"] for name, node in scene.items() if name.startswith("/chute/touchdowns/")]
    assert len(markers) == len(touchdowns), "the run's touchdowns, marked again"


def test_a_view_that_first_sees_a_run_under_way_draws_it_from_its_first_frame(server):
    live = Live(server)
    for k in range(50):  # the robot standing before the run: frames the view has drawn
        live.robot.tracker.add(Pose(0.01 * k, 0.0, 0.05, 0.0))
    live.frame()
    first = live.robot.tracker.count()
    live.robot.run = RunSnapshot(run_id=1, started=time.time(), jumps=100, max_seconds=60.0, first_pose=first)
    path = climb(np.arange(0.0, 2.0, 1 / TRACKER_RATE), 0.1)
    for t, (x, y) in zip(np.arange(0.0, 2.0, 1 / TRACKER_RATE), path, strict=True):
        live.robot.tracker.add(Pose(float(t), float(x), float(y), 0.0))
    live.mode.scene.clear_history()  # the browser was in another mode meanwhile, and comes back to live
    live.mode.activate()
    live.frame()
    scene, _ = live.recorded()[-1]
    assert trail_drawn(scene) == segments_of(path), "the run's own frames, from its first: none from before it"


@dataclass
class Status:
    """The robot service as the readout reads it: its tracker, and its status with the tracker's counts."""

    tracker: PoseHistory
    received: int

    def status(self) -> dict:
        tracker = {"received": self.received, "loss": 0.0, "latest": None}
        return {"state": "disarmed", "tracker": tracker}


def test_the_readout_tells_frames_without_the_body_from_no_frames(server):
    """It said "2488 frames … no frames yet" when frames came without the robot's body in them."""
    lock = threading.RLock()
    for received, words in ((0, "no frames yet"), (2488, "no pose of the robot's body in them yet")):
        mode = LiveMode(server, ChuteScene(server.scene, ROBOT), lock, Status(PoseHistory(Calibration()), received))
        readout = mode.readout(60.0)
        assert f"{received} frames" in readout and words in readout
        assert received == 0 or "no frames yet" not in readout
