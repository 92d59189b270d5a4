"""``parkour climb``: a climb in a world — walls at angles, footholds (docs/model.md §8)."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import (
    ControlsOption,
    JsonOption,
    ModelSetup,
    SeedOption,
    handles_errors,
    parse_controls,
    print_json,
    with_model,
    with_noise,
)
from sim_core.model.noise import NoiseModel

app = typer.Typer(rich_markup_mode=None)

WorldOption = Annotated[
    str,
    typer.Option(
        "--world",
        help="A world file (.json, docs/worlds.md) or a named world (parkour world list).",
    ),
]


@app.command("climb")
@handles_errors
@with_model
@with_noise
def climb_command(
    world: WorldOption,
    state: Annotated[
        tuple[float, float],
        typer.Option(
            "--state",
            help="The body's velocity XDOT YDOT at touchdown 0 [sqrt(g l0)], xdot < 0: arriving at the left side.",
        ),
    ],
    setup: ModelSetup,
    noise: NoiseModel,
    controls: ControlsOption = "30:0.9",
    foot_y: Annotated[
        float, typer.Option("--foot-y", help="Height of touchdown 0's foot on the left side [l0].")
    ] = 0.0,
    jumps: Annotated[int, typer.Option("--jumps", help="Number of jumps.", min=0, max=1_000_000)] = 10,
    noisy: Annotated[
        bool, typer.Option("--noise", help="Apply the noise options (docs/model.md §5.1, pitch included); off: none.")
    ] = False,
    seed: SeedOption = 0,
    floor: Annotated[bool, typer.Option("--floor", help="End the climb at a touchdown below the floor.")] = False,
    as_json: JsonOption = False,
) -> None:
    """Climb a world: the body at every touchdown in wall coordinates [l0], and how the climb ended.

    No noise, pitch or floor unless asked: --noise (with the noise options, drawn from --seed),
    --floor (docs/model.md §8)."""
    from sim_core.world.climb import climb_world
    from sim_core.world.named import resolve_world

    chosen, _description = resolve_world(world, setup.model.d_hat, setup.robot.scales.length)
    climb = climb_world(setup.model, chosen, parse_controls(controls), state, jumps, foot_y=foot_y,
                        noise=noise if noisy else None, seed=seed, floor=floor)  # fmt: skip
    result = climb.to_dict()
    if as_json:
        print_json(result)
        return
    from rich.console import Console
    from rich.table import Table

    title = f"climb in {chosen.name or world}, controls {controls} (wall coordinates, l0)"
    table = Table("jump", "side", "segment", "x", "y", "xdot", "ydot", title=title)
    for row in result["touchdowns"]:
        numbers = (f"{row[key]:.6f}" for key in ("x", "y", "xdot", "ydot"))
        table.add_row(str(row["jump"]), row["side"], str(row["segment"]), *numbers)
    console = Console()
    console.print(table)
    if climb.failure is not None:
        console.print(f"failed at jump {climb.failed_jump}: {climb.failure.code} — {climb.failure.message}")
