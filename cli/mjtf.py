"""``parkour mjtf``: Mean Jumps To Failure under noise, per energy level (paper Fig. 11)."""

from __future__ import annotations

from typing import Annotated

import numpy as np
import typer

from cli.options import (
    GuessOption,
    JsonOption,
    ModelSetup,
    SchedulerOption,
    SeedOption,
    handles_errors,
    option_named,
    print_json,
    with_model,
    with_noise,
)
from cli.studies import fixed_leg_of, over_zeta0
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NoiseModel
from sim_core.model.validation import check_range

app = typer.Typer(rich_markup_mode=None)


@app.command("mjtf")
@handles_errors
@with_model
@with_noise
def mjtf_command(
    setup: ModelSetup,
    noise: NoiseModel,
    psi0: Annotated[float, typer.Option("--psi0", help="Leg angle [degrees].")] = 30.0,
    zeta0_range: Annotated[
        tuple[float, float], typer.Option("--zeta0-range", help="LOW HIGH of zeta0 over the energy levels.")
    ] = (0.84, 0.96),
    levels: Annotated[int, typer.Option("--levels", help="Number of energy levels.")] = 10,
    zeta0: Annotated[
        list[float] | None,
        typer.Option("--zeta0", help="A level's zeta0, instead of the range (repeat for several; once: one level)."),
    ] = None,
    trials: Annotated[int, typer.Option("--trials", help="Trials per level.")] = 8,
    cap: Annotated[int, typer.Option("--cap", help="Jumps after which a trial counts as survived.")] = 1000,
    seed: SeedOption = 0,
    fixed_leg: Annotated[
        str | None, typer.Option("--fixed-leg", help="PSI0:ZETA0 of a leg held fixed; the other sweeps.")
    ] = None,
    guess: GuessOption = None,
    world: Annotated[
        str | None,
        typer.Option("--world", help="Climb in this world (a file or a named world, docs/worlds.md) from touchdown 0."),
    ] = None,
    foot_y: Annotated[float, typer.Option("--foot-y", help="With --world: touchdown 0's foot height [l0].")] = 0.0,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Mean Jumps To Failure under noise, per energy level (zeta0); with --world, climbing that
    world from touchdown 0 at each level's gait velocity, ending at its floor too."""
    from sim_core.basins.sweep import zeta0_values
    from sim_core.robustness.mjtf import CAPPED, check_trials, mjtf_study

    if zeta0:
        zeta0s = np.array([check_range("--zeta0", value, 0.0, 1.0) for value in zeta0])
        if len(set(zeta0)) != len(zeta0):
            raise ParameterError("--zeta0", f"must name each level once, got {', '.join(f'{z:g}' for z in zeta0)}")
        levels = len(zeta0s)
    else:
        with option_named("--levels", "steps"):
            zeta0s = zeta0_values(*zeta0_range, levels)
    check_trials(trials, cap)
    study = over_zeta0(
        mjtf_study,
        f"MJTF: {levels} levels x {trials} trials",
        scheduler,
        setup,
        psi0,
        zeta0s,
        fixed_leg_of(fixed_leg),
        guess,
        noise=noise,
        trials=trials,
        cap=cap,
        seed=seed,
        **_in_world(world, foot_y, setup),
    )
    if as_json:
        print_json(study.to_dict())
        return
    from rich.console import Console
    from rich.table import Table

    where = "" if study.world is None else f", in {study.world} from foot height {foot_y:g} l0"
    table = Table("zeta0", "E (m g l0)", "MJTF", "std", "95% CI", "capped", "failures", title=f"psi0 {psi0:g}°{where}")
    for level in study.levels:
        outcomes = level.histogram()
        capped = outcomes.pop(CAPPED)
        low, high = level.ci95
        table.add_row(
            f"{level.zeta0:.4f}",
            f"{level.energy:.3f}",
            f"{level.mean:.1f}",
            f"{level.std:.1f}",
            f"{low:.1f} … {high:.1f}",
            f"{capped}/{level.jumps.size}",
            ", ".join(f"{code} {count}" for code, count in outcomes.items() if count),
        )
    Console().print(table)


def _in_world(world: str | None, foot_y: float, setup: ModelSetup) -> dict:
    """The study's world options: none without ``--world`` (``--foot-y`` then means nothing)."""
    if world is None:
        if foot_y != 0.0:
            raise ParameterError("--foot-y", "needs --world: on the map's parallel walls trials have no height")
        return {}
    from sim_core.world.named import resolve_world

    chosen, _description = resolve_world(world, setup.model.d_hat, setup.robot.scales.length)
    return {"world": chosen, "foot_y": foot_y}
