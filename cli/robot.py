"""``parkour robot-sim``: the virtual robot, speaking protocol v1 on a TCP socket."""

from __future__ import annotations

import time
from typing import Annotated

import typer

from cli.options import handles_errors, note
from sim_core.errors import ParameterError

app = typer.Typer(rich_markup_mode=None)


@app.command("robot-sim")
@handles_errors
def robot_sim_command(
    host: Annotated[str, typer.Option("--host", help="Interface to listen on.")] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port of the robot's 'radio'.", min=1, max=65535)] = 9750,
    tracker: Annotated[
        str, typer.Option("--tracker", help="HOST:PORT to stream the 100 Hz tracker datagrams to.")
    ] = "127.0.0.1:9751",
    seed: Annotated[int, typer.Option("--seed", help="Seed of the robot's imperfections.")] = 0,
    tracker_protocol: Annotated[
        str, typer.Option("--tracker-protocol", help="pkt1 (ParkourLab datagrams) or natnet (the camera software's).")
    ] = "pkt1",
    natnet_version: Annotated[
        str, typer.Option("--natnet-version", help="NatNet version streamed (2.0 to 4.x).")
    ] = "3.1",
    natnet_rigid_body_id: Annotated[
        int, typer.Option("--natnet-rigid-body-id", help="The body's NatNet rigid body id.", min=0)
    ] = 1,
) -> None:
    """Run the virtual robot until Ctrl-C; connect with the pyserial URL socket://HOST:PORT."""
    from backend.robot.virtual import VirtualRobot

    tracker_host, _, tracker_port = tracker.rpartition(":")
    if not tracker_host or not tracker_port.isdigit():
        raise ParameterError("tracker", f"must be HOST:PORT, got {tracker!r}")
    natnet = {"natnet_version": natnet_version, "natnet_rigid_body_id": natnet_rigid_body_id}
    robot = VirtualRobot(
        host, port, tracker_to=(tracker_host, int(tracker_port)), seed=seed, tracker_protocol=tracker_protocol, **natnet
    ).start()
    note(
        f"virtual robot listening: {robot.url}  tracker ({tracker_protocol}) to udp://{tracker}"
        "  (docs/protocol.md; Ctrl-C stops it)"
    )
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        robot.stop()
