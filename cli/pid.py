"""``parkour pid``: the closed-loop climb to a target height (paper Fig. 12)."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import JsonOption, ModelSetup, SeedOption, handles_errors, print_json, with_model, with_noise
from sim_core.control.height_controller import HeightController
from sim_core.model.noise import NO_NOISE, NoiseModel

app = typer.Typer(rich_markup_mode=None)


@app.command("pid")
@handles_errors
@with_model
@with_noise
def pid_command(
    setup: ModelSetup,
    noise: NoiseModel,
    target: Annotated[float, typer.Option("--target", help="Height to hold [m] (the robot's l0 converts it).")] = 0.55,
    psi0: Annotated[float, typer.Option("--psi0", help="Leg angle [degrees].")] = 35.0,
    start_zeta0: Annotated[float, typer.Option("--start-zeta0", help="zeta0 of the climbing gait at the start.")] = 0.9,
    jumps: Annotated[int, typer.Option("--jumps", help="Jumps to simulate.")] = 80,
    kp: Annotated[float, typer.Option("--kp", help="Proportional gain [zeta0 per l0].")] = HeightController.kp,
    ki: Annotated[float, typer.Option("--ki", help="Integral gain [zeta0 per l0 jump].")] = HeightController.ki,
    kd: Annotated[float, typer.Option("--kd", help="Derivative gain [zeta0 jump per l0].")] = HeightController.kd,
    zeta0_min: Annotated[
        float, typer.Option("--zeta0-min", help="Leg range: most retraction.")
    ] = HeightController.zeta0_min,
    zeta0_max: Annotated[
        float, typer.Option("--zeta0-max", help="Leg range: least retraction.")
    ] = HeightController.zeta0_max,
    noisy: Annotated[bool, typer.Option("--noisy", help="Apply the noise model (options as for mjtf).")] = False,
    seed: SeedOption = 0,
    as_json: JsonOption = False,
) -> None:
    """Closed-loop climb to a target height: a PID on the touchdown height sets the next zeta0."""
    from experiments.fig12 import Config, PidClimb

    scales = setup.robot.scales
    config = Config(target_m=target, psi0_deg=psi0, start_zeta0=start_zeta0, jumps=jumps, kp=kp, ki=ki, kd=kd,
                    zeta0_min=zeta0_min, zeta0_max=zeta0_max)  # fmt: skip
    loop = PidClimb.of(setup.model, config, scales.length)
    hover = loop.hover
    run = loop.climb(noise if noisy else NO_NOISE, seed)
    result = run.to_dict()
    result["si"] = {
        "target_m": target,
        "height_m": (run.height * scales.length).tolist(),
        "time_s": (run.time * scales.time).tolist(),
        "rise_time_s": run.rise_time() * scales.time,
        "steady_error_m": run.steady_error() * scales.length,
    }
    result["noise"] = noise.to_dict() if noisy else None
    if as_json:
        print_json(result)
        return
    from rich.console import Console
    from rich.table import Table

    settled = run.settling_jump()
    table = Table("measure", "value", title=f"Closed-loop climb to {target:g} m, psi0 {psi0:g}°")
    table.add_row("hover zeta0 (feed-forward)", f"{hover:.5f}")
    table.add_row("gains kp, ki, kd", f"{kp:g}, {ki:g}, {kd:g}")
    table.add_row("outcome", "completed" if run.failure is None else f"failed: {run.failure.code}")
    table.add_row("rise time (10-90%)", f"{run.rise_time() * scales.time:.2f} s")
    table.add_row("overshoot", f"{run.overshoot():.1%}")
    table.add_row(
        "settled (±2%)", "no" if settled is None else f"jump {settled}, {run.time[settled] * scales.time:.2f} s"
    )
    table.add_row("steady error", f"{run.steady_error() * scales.length * 100:.2f} cm")
    table.add_row("final height", f"{run.height[-1] * scales.length * 100:.2f} cm")
    Console().print(table)
