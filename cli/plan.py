"""``parkour plan``: the most robust way up a world, foothold by foothold (docs/worlds.md)."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import JsonOption, ModelSetup, SeedOption, handles_errors, note, print_json, with_model, with_noise
from sim_core.model.errors import ParameterError
from sim_core.model.noise import NoiseModel

app = typer.Typer(rich_markup_mode=None)


@app.command("plan")
@handles_errors
@with_model
@with_noise
def plan_command(
    world: Annotated[str, typer.Option("--world", help="A world file (.json) or a named world (parkour world list).")],
    goal_height: Annotated[float, typer.Option("--goal-height", help="The height the feet must reach [m].")],
    setup: ModelSetup,
    noise: NoiseModel,
    state: Annotated[
        tuple[float, float] | None,
        typer.Option("--state", help="The body's velocity XDOT YDOT at touchdown 0; default: the 30:0.9 gait's."),
    ] = None,
    foot_y: Annotated[float, typer.Option("--foot-y", help="Touchdown 0's foot height on the left side [l0].")] = 0.0,
    seed: SeedOption = 0,
    mfpt: Annotated[
        bool,
        typer.Option(
            "--mfpt",
            help="Also the chance that a climb of the plan fails and its mean jumps to failure, "
            "the placement law following it under the noise options, by splitting.",
        ),
    ] = False,
    replicas: Annotated[
        int | None, typer.Option("--replicas", help="With --mfpt: attempts a run (default 40).")
    ] = None,
    runs: Annotated[int | None, typer.Option("--runs", help="With --mfpt: independent runs (default 64).")] = None,
    replans: Annotated[
        int | None, typer.Option("--replans", help="With --mfpt: replans an attempt may make (default 3).")
    ] = None,
    monte_carlo: Annotated[
        int | None,
        typer.Option("--monte-carlo", help="With --mfpt: as many plain attempts beside it, to check it (1-100000)."),
    ] = None,
    importance_sampling: Annotated[
        int | None,
        typer.Option(
            "--importance-sampling",
            help="With --mfpt: as many importance-sampled climbs beside it, the noise widened and each climb "
            "weighed by its draws: for rare failures (2-100000).",
        ),
    ] = None,
    is_scale: Annotated[
        float | None,
        typer.Option(
            "--is-scale", help="With --importance-sampling: the factor on the widened sigmas (1-5, default 1.5)."
        ),
    ] = None,
    is_draws: Annotated[
        str | None,
        typer.Option(
            "--is-draws",
            help="With --importance-sampling: the draws widened, comma-separated of psi0, zeta0, velocity, pitch "
            "(default all).",
        ),
    ] = None,
    is_first_leg: Annotated[
        bool,
        typer.Option("--is-first-leg", help="With --importance-sampling: widen touchdown 0's draws only."),
    ] = False,
    as_json: JsonOption = False,
) -> None:
    """A sequence of footholds and leg commands from touchdown 0 to --goal-height, the most robust
    under the noise options (each jump's share of noisy draws that land and hold, multiplied);
    with --mfpt, how often the placement law's climbs of it fail (docs/worlds.md)."""
    from cli.plan_mfpt import check_importance_options, check_mfpt_options

    splitting = check_mfpt_options(mfpt, replicas, runs, replans, monte_carlo, seed)
    importance = check_importance_options(mfpt, importance_sampling, is_scale, is_draws, is_first_leg)
    from sim_core.planning.launch import start_velocity
    from sim_core.planning.planner import plan_climb
    from sim_core.world.named import resolve_world

    chosen, _description = resolve_world(world, setup.model.d_hat, setup.robot.scales.length)
    metres = setup.robot.scales.length
    start_m, top_m = foot_y * metres, chosen.top * metres
    if not start_m < goal_height <= top_m:  # said in metres, as asked (the library speaks l0)
        raise ParameterError("--goal-height", f"must be above the start's foot ({start_m:.3f} m) and at most "
                             f"{chosen.name}'s top ({top_m:.3f} m), got {goal_height:g} m")  # fmt: skip
    if state is None:
        state = start_velocity(setup.model)
        note(f"touchdown 0 at the 30:0.9 gait's velocity {[round(v, 4) for v in state]}")
    plan = plan_climb(setup.model, chosen, goal_height / metres, state, foot_y=foot_y, noise=noise, seed=seed)
    if not plan.reaches_goal:
        raise ParameterError(
            "goal_height", f"no plan reaches {goal_height:g} m in {chosen.name}: the highest reachable is "
            f"{plan.highest * metres:.3f} m"
        )  # fmt: skip
    document = plan.to_dict(metres)
    if splitting is not None:
        from cli.plan_mfpt import plan_mfpt_document

        document["mfpt"] = plan_mfpt_document(setup.model, chosen, plan, goal_height / metres, noise, splitting,
                                              monte_carlo, importance)  # fmt: skip
    if as_json:
        print_json(document)
        return
    from rich.console import Console
    from rich.table import Table

    title = f"plan up {chosen.name} to {goal_height:g} m: estimated chance {plan.chance:.0%} ({plan.seconds:.2f} s)"
    table = Table("jump", "side", "segment", "foot x [l0]", "foot y [l0]", "psi0 [deg]", "zeta0", title=title)
    for row in document["plan"]:
        table.add_row(str(row["jump"]), row["side"], str(row["segment"]), f"{row['target'][0]:.3f}",
                      f"{row['target'][1]:.3f}", f"{row['psi0_deg']:.1f}", f"{row['zeta0']:.3f}")  # fmt: skip
    Console().print(table)
    if splitting is not None:
        from cli.plan_mfpt import print_mfpt

        print_mfpt(document["mfpt"])
