"""``parkour robot-sim``: the virtual robot, speaking protocol v1 on a TCP socket."""

from __future__ import annotations

import time
from typing import Annotated

import typer

from backend.cli.options import handles_errors, note

app = typer.Typer(rich_markup_mode=None)


@app.command("robot-sim")
@handles_errors
def robot_sim_command(
    host: Annotated[str, typer.Option("--host", help="Interface to listen on.")] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port of the robot's 'radio'.", min=1, max=65535)] = 9750,
) -> None:
    """Run the virtual robot until Ctrl-C; connect with the pyserial URL socket://HOST:PORT."""
    from backend.robot.virtual import VirtualRobot

    robot = VirtualRobot(host, port).start()
    note(f"virtual robot listening: {robot.url}  (protocol v1, docs/protocol.md; Ctrl-C stops it)")
    try:
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        pass
    finally:
        robot.stop()
