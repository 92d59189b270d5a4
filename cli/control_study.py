"""``parkour control-study``: the standard closed-loop benchmark, every controller on the same noise."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import JsonOption, ModelSetup, SchedulerOption, handles_errors, print_json, with_model, with_noise
from cli.studies import run_study
from sim_core.control.registry import NAMES
from sim_core.model.noise import NoiseModel

app = typer.Typer(rich_markup_mode=None)


def parse_controllers(text: str) -> tuple[str, ...]:
    """``pid,pid-pitch`` as names, in order, each once; a ParameterError naming ``controllers``."""
    from experiments.control_study import check_controllers

    return check_controllers(name.strip() for name in text.split(",") if name.strip())


@app.command("control-study")
@handles_errors
@with_model
@with_noise
def control_study_command(
    setup: ModelSetup,
    noise: NoiseModel,
    controllers: Annotated[
        str, typer.Option("--controllers", help=f"Comma-separated, of: {', '.join(NAMES)}.")
    ] = ",".join(NAMES),
    target: Annotated[float, typer.Option("--target", help="Height to hold [m].")] = 0.55,
    seeds: Annotated[int, typer.Option("--seeds", help="Trials per controller (seeds seed0, seed0 + 1, ...).")] = 200,
    seed0: Annotated[int, typer.Option("--seed0", help="The first trial's seed (>= 0).")] = 0,
    jumps: Annotated[int, typer.Option("--jumps", help="Jumps per trial.")] = 400,
    psi0: Annotated[float, typer.Option("--psi0", help="Nominal leg angle [degrees].")] = 35.0,
    start_zeta0: Annotated[float, typer.Option("--start-zeta0", help="zeta0 of the climbing gait at the start.")] = 0.9,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Every controller climbing to a target height under noise, on the same noise draws: failures,
    height error once risen, jumps to rise, clipped commands, the law's time per jump."""
    from experiments.control_study import Config, run

    config = Config(controllers=parse_controllers(controllers), target_m=target, psi0_deg=psi0,
                    start_zeta0=start_zeta0, jumps=jumps, seeds=seeds, seed0=seed0, noise=noise)  # fmt: skip
    description = f"control study: {len(config.controllers)} controllers x {seeds} trials"
    result = run_study(run, description, scheduler, setup.model, setup.robot.scales.length, config).to_dict()
    if as_json:
        print_json(result)
        return
    from rich.console import Console
    from rich.table import Table

    title = f"{seeds} trials × {jumps} jumps to {target:g} m, the same noise for each"
    table = Table("controller", "failures", "jumps to failure", "height RMS", "median |error|", "rise [jumps]",
                  "clipped", "µs/jump", title=title)  # fmt: skip

    def cm(value: float | None) -> str:
        return "—" if value is None else f"{value * 100:.2f} cm"

    for entry in result["controllers"]:
        rise = "—" if entry["rise_jumps"] is None else f"{entry['rise_jumps']:g}"
        lasted = f"{'≥ ' if entry['survived'] else ''}{entry['mean_jumps_to_failure']:.0f}"
        table.add_row(entry["name"], f"{entry['failures']}/{entry['trials']}", lasted, cm(entry["height_rms_m"]),
                      cm(entry["height_median_abs_m"]), rise, f"{entry['saturated_fraction']:.1%}",
                      f"{entry['us_per_jump']:.3f}")  # fmt: skip
    Console().print(table)
