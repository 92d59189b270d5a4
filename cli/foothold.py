"""``parkour foothold-study``: foot placement following a plan against the best fixed schedule, on
many worlds, every method on the same noise draws (docs/worlds.md, "The foothold study")."""

from __future__ import annotations

from contextlib import ExitStack
from typing import Annotated

import typer

from cli.options import (
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
from cli.studies import run_study
from cli.world import OPTION_OF_FIELD as WORLD_OPTIONS
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NoiseModel
from sim_core.world.named import CHUTE_HEIGHT
from sim_core.world.random_world import GAP, HOLD_LENGTH, INCLINE_DEG, MU

app = typer.Typer(rich_markup_mode=None)
Interval = tuple[float, float]
# random_world's arguments as the options that give them here: parkour world random's, but the seeds
# are --seed0 (--seed is the trials') and the friction --hold-mu (--mu is the model's); the width is the model's
OPTION_OF_FIELD = {field: option for field, option in WORLD_OPTIONS.items() if field != "width"} | {
    "seed": "--seed0", "mu": "--hold-mu"}  # fmt: skip
MAX_RANDOM = 1000


@app.command("foothold-study")
@handles_errors
@with_model
@with_noise
def foothold_study_command(
    goal_height: Annotated[float, typer.Option("--goal-height", help="The height the feet must reach [m].")],
    trials: Annotated[int, typer.Option("--trials", help="Noisy trials per world and method.")],
    setup: ModelSetup,
    noise: NoiseModel,
    worlds: Annotated[
        str | None, typer.Option("--worlds", help="Comma-separated world files (.json) or named worlds.")
    ] = None,
    random: Annotated[int | None, typer.Option("--random", help=f"Random-foothold worlds, 1 to {MAX_RANDOM}.")] = None,
    seed0: Annotated[int, typer.Option("--seed0", help="The first random world's seed (then seed0 + 1, ...).")] = 0,
    holds: Annotated[int | None, typer.Option("--holds", help="Random worlds: footholds per side.")] = None,
    incline_deg: Annotated[Interval, typer.Option("--incline-deg", help="Random worlds: LOW HIGH beta [deg].")] = (
        INCLINE_DEG
    ),
    hold_mu: Annotated[
        Interval,
        typer.Option("--hold-mu", help="Random worlds: LOW HIGH of the footholds' friction (--mu is the model's)."),
    ] = MU,
    gap: Annotated[Interval, typer.Option("--gap", help="Random worlds: LOW HIGH of the rise without grip [l0].")] = (
        GAP
    ),
    hold_length: Annotated[
        Interval, typer.Option("--hold-length", help="Random worlds: LOW HIGH of the footholds' length [l0].")
    ] = HOLD_LENGTH,
    height: Annotated[float, typer.Option("--height", help="Random worlds: the sides' top [l0].")] = CHUTE_HEIGHT,
    state: Annotated[
        tuple[float, float] | None,
        typer.Option("--state", help="The body's velocity XDOT YDOT at touchdown 0; default: the 30:0.9 gait's."),
    ] = None,
    cap: Annotated[int, typer.Option("--cap", help="Most jumps per trial.")] = 200,
    seed: SeedOption = 0,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Foot placement following a plan against the best fixed schedule a reach search finds, on
    the worlds named or on random-foothold worlds, every method on the same noise draws: how many
    trials reach --goal-height, how the others fail, the planning's time and the law's."""
    from sim_core.planning.goals import check_goal
    from sim_core.planning.study import foothold_study
    from sim_core.world.named import resolve_world
    from sim_core.world.random_world import random_world

    if (worlds is None) == (random is None):
        raise ParameterError("--worlds", "give either --worlds W1,W2,... or --random N, not both and not neither")
    metres, model = setup.robot.scales.length, setup.model
    chosen = []
    if worlds is not None:
        names = [name.strip() for name in worlds.split(",") if name.strip()]
        if not names:
            raise ParameterError("--worlds", "must name at least one world")
        for name in names:
            world, _description = resolve_world(name, model.d_hat, metres)
            chosen.append((name, world))
    else:
        if not 1 <= random <= MAX_RANDOM:
            raise ParameterError("--random", f"must be 1 to {MAX_RANDOM}, got {random}")
        with ExitStack() as said_as_options:
            for field, option in OPTION_OF_FIELD.items():
                said_as_options.enter_context(option_named(option, field))
            for index in range(random):
                world = random_world(seed0 + index, holds, incline_deg, hold_mu, gap, hold_length, model.d_hat, height)
                chosen.append((f"random:{seed0 + index}", world))
    goal = goal_height / metres
    with option_named("--goal-height", "goal_height"):
        for name, world in chosen:
            check_goal(world, goal, 0.0, name=name, metres=metres)
    with option_named("--trials", "trials"), option_named("--seed", "seed"), option_named("--cap", "cap"):
        study = run_study(foothold_study, f"foothold study: {len(chosen)} worlds x {trials} trials", scheduler,
                          model, chosen, goal, state, trials=trials, seed=seed, noise=noise, cap=cap)  # fmt: skip
    document = study.to_dict(metres)
    if as_json:
        print_json(document)
        return
    from rich.console import Console
    from rich.table import Table

    table = Table("method", "reached", "trials", "failures", "mean jumps", "plan s (median)", "law µs/jump",
                  title=f"foothold study to {goal_height:g} m")  # fmt: skip
    for name, method in document["methods"].items():
        failures = ", ".join(f"{code} {count}" for code, count in method["failures_by_code"].items()) or "-"
        law = "-" if method["law_us_per_jump"] is None else f"{method['law_us_per_jump']:.0f}"
        mean = "-" if method["mean_jumps"] is None else f"{method['mean_jumps']:.1f}"
        table.add_row(name, str(method["reached"]), str(method["trials"]), failures, mean,
                      f"{method['plan_seconds_median']:.2f}", law)  # fmt: skip
    console = Console()
    console.print(table)
    for row in document["worlds"]:
        console.print(f"{row['world']}: plan {'yes' if row['plan_exists'] else 'none'}, reached open-loop "
                      f"{row['reached']['open-loop']}/{row['trials']}, placement {row['reached']['placement']}/"
                      f"{row['trials']}")  # fmt: skip
