"""``parkour robot-sim``: the virtual robot, speaking protocol v1 on a TCP socket."""

from __future__ import annotations

import time
from enum import StrEnum
from typing import Annotated

import typer

from cli.options import ModelSetup, handles_errors, note, with_model
from sim_core.model.errors import ParameterError

app = typer.Typer(rich_markup_mode=None)


class Noise(StrEnum):
    off = "off"
    on = "on"


@app.command("robot-sim")
@handles_errors
@with_model
def robot_sim_command(
    host: Annotated[str, typer.Option("--host", help="Interface to listen on.")] = "127.0.0.1",
    port: Annotated[int, typer.Option("--port", help="TCP port of the robot's 'radio'.", min=1, max=65535)] = 9750,
    tracker: Annotated[
        str, typer.Option("--tracker", help="HOST:PORT to stream the 100 Hz tracker datagrams to.")
    ] = "127.0.0.1:9751",
    seed: Annotated[int, typer.Option("--seed", help="Seed of the robot's imperfections.")] = 0,
    psi0_offset_deg: Annotated[
        tuple[float, float],
        typer.Option("--psi0-offset-deg", help="L R: what each leg's psi0 is beyond the commanded one [deg]."),
    ] = (0.0, 0.0),
    zeta0_offset: Annotated[
        tuple[float, float],
        typer.Option("--zeta0-offset", help="L R: what each leg's zeta0 is beyond the commanded one [l0]."),
    ] = (0.0, 0.0),
    noise: Annotated[
        Noise,
        typer.Option(
            "--noise", help="on: control, pitch and state noise, tracker noise and dropped frames; off: none."
        ),
    ] = Noise.on,
    tracker_protocol: Annotated[
        str, typer.Option("--tracker-protocol", help="pkt1 (ParkourLab datagrams) or natnet (the camera software's).")
    ] = "pkt1",
    natnet_version: Annotated[
        str, typer.Option("--natnet-version", help="NatNet version streamed (2.0 to 4.x).")
    ] = "3.1",
    natnet_rigid_body_id: Annotated[
        int, typer.Option("--natnet-rigid-body-id", help="The body's NatNet rigid body id.", min=0)
    ] = 1,
    *,
    setup: ModelSetup,
    world: Annotated[
        str | None,
        typer.Option("--world", help="The chute it climbs: a world file or a named world (docs/worlds.md)."),
    ] = None,
) -> None:
    """Run the virtual robot until Ctrl-C; connect with the pyserial URL socket://HOST:PORT.

    Its true physics are the model options (--preset --alpha --d-hat --c-zeta --c-psi --mu) and its
    imperfections --psi0-offset-deg, --zeta0-offset and --noise: the truth a calibration should recover
    (docs/calibration.md).
    """
    from backend.robot.virtual import VirtualRobot
    from sim_core.model.controls import LegOffsets
    from sim_core.model.noise import NO_NOISE

    imperfections = {} if noise is Noise.on else {"noise": NO_NOISE, "tracker_noise": 0.0, "drop_rate": 0.0}
    offsets = LegOffsets(psi0_offset_deg=psi0_offset_deg, zeta0_offset=zeta0_offset)

    tracker_host, _, tracker_port = tracker.rpartition(":")
    if not tracker_host or not tracker_port.isdigit():
        raise ParameterError("tracker", f"must be HOST:PORT, got {tracker!r}")
    natnet = {"natnet_version": natnet_version, "natnet_rigid_body_id": natnet_rigid_body_id}
    if world is not None:
        from sim_core.world.named import resolve_world

        imperfections["world"] = resolve_world(world, setup.model.d_hat, setup.robot.scales.length)[0]
    robot = VirtualRobot(host, port, tracker_to=(tracker_host, int(tracker_port)), seed=seed,
                         tracker_protocol=tracker_protocol, robot=setup.robot, leg_offsets=offsets,
                         **natnet, **imperfections).start()  # fmt: skip
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
