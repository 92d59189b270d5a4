"""``parkour world list|show|random``: the worlds of general chutes (docs/worlds.md, docs/model.md §8).

A world is a named one (``parkour world list``) or a world file; ``show`` prints either as the
world file it is, in ``l0``, and ``random`` writes a world file of random footholds. A named world
and a random one are built for the chute's width ``d_hat`` of ``--preset`` (or ``--d-hat``); a
world file in metres is converted with the preset's ``l0``.
"""

from __future__ import annotations

import math
from contextlib import ExitStack
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from cli.options import JsonOption, SeedOption, build_setup, handles_errors, option_named, print_json
from sim_core.model.presets import DEFAULT_PRESET
from sim_core.world.files import save_world, world_to_document
from sim_core.world.named import CHUTE_HEIGHT, NAMED_WORLDS, resolve_world
from sim_core.world.random_world import GAP, HOLD_LENGTH, INCLINE_DEG, MAX_HOLDS, MU, random_world
from sim_core.world.world import SIDES, World, inclinations

app = typer.Typer(name="world", help="Worlds of general chutes: list the named ones, show one, make random footholds.",
                  no_args_is_help=True, rich_markup_mode=None)  # fmt: skip

PresetOption = Annotated[
    str,
    typer.Option(
        "--preset",
        help="Named parameter set (docs/model.md §1), or one parkour calibrate stored: its d_hat is the chute's "
        "width, its l0 converts a world file in metres.",
    ),
]
DHatOption = Annotated[
    float | None,
    typer.Option("--d-hat", help="Override d_hat = d/l0, the chute's width [l0], > 0.", show_default=False),
]
Interval = tuple[float, float]
# random_world's arguments as the options that give them.
OPTION_OF_FIELD = {"seed": "--seed", "holds": "--holds", "incline_deg": "--incline-deg", "mu": "--mu", "gap": "--gap",
                   "hold_length": "--hold-length", "width": "--d-hat", "height": "--height"}  # fmt: skip


@app.command("list")
@handles_errors
def list_command(as_json: JsonOption = False) -> None:
    """The named worlds and what each is."""
    rows = [{"name": name, "description": entry.description} for name, entry in NAMED_WORLDS.items()]
    if as_json:
        print_json(rows)
        return
    for row in rows:
        typer.echo(f"{row['name']:<10}  {row['description']}")


@app.command("show")
@handles_errors
def show_command(
    world: Annotated[str, typer.Argument(help="A named world (parkour world list) or a world file (.json).")],
    preset: PresetOption = DEFAULT_PRESET,
    d_hat: DHatOption = None,
    as_json: JsonOption = False,
) -> None:
    """A world as its world file in l0 (--json), or as a table of its segments."""
    setup = build_setup(preset, d_hat=d_hat)
    chosen, description = resolve_world(world, setup.model.d_hat, setup.robot.leg_length)
    if as_json:
        print_json(world_to_document(chosen, "l0", description=description))
        return
    _print_segments(chosen, description)


@app.command("random")
@handles_errors
def random_command(
    out: Annotated[Path, typer.Option("--out", help="The world file to write (JSON, in l0).")],
    seed: SeedOption = 0,
    holds: Annotated[
        int | None,
        typer.Option("--holds", help=f"Footholds per side, 1 to {MAX_HOLDS}; default: as many as end below --height."),
    ] = None,
    incline_deg: Annotated[
        Interval,
        typer.Option("--incline-deg", help="LOW HIGH of the footholds' inclination beta [deg] (> 0 faces upward)."),
    ] = INCLINE_DEG,
    mu: Annotated[Interval, typer.Option("--mu", help="LOW HIGH of the footholds' friction, >= 0.")] = MU,
    gap: Annotated[
        Interval, typer.Option("--gap", help="LOW HIGH of the rise without grip between footholds [l0].")
    ] = GAP,
    hold_length: Annotated[
        Interval, typer.Option("--hold-length", help="LOW HIGH of the footholds' length [l0].")
    ] = HOLD_LENGTH,
    height: Annotated[
        float, typer.Option("--height", help="The sides' top [l0]; default 2 m in the paper's l0.")
    ] = CHUTE_HEIGHT,
    preset: PresetOption = DEFAULT_PRESET,
    d_hat: DHatOption = None,
    as_json: JsonOption = False,
) -> None:
    """Write a world of random footholds: the same seed and options give the same world."""
    width = build_setup(preset, d_hat=d_hat).model.d_hat
    with ExitStack() as said_as_options:  # "--incline-deg: must be ...", not the library's "incline_deg"
        for field, option in OPTION_OF_FIELD.items():
            said_as_options.enter_context(option_named(option, field))
        world = random_world(seed, holds, incline_deg, mu, gap, hold_length, width, height)
    description = (
        f"random footholds, seed {seed}: {'as many as fit' if holds is None else holds} per side, "
        f"incline {_span(incline_deg)} deg, mu {_span(mu)}, gap {_span(gap)} l0, length {_span(hold_length)} l0, "
        f"width {width:g} l0, height {height:g} l0"
    )
    save_world(world, out, description=description)
    segments = {"left": world.left.segments, "right": world.right.segments}
    if as_json:
        print_json({"out": str(out), "name": world.name, "segments": segments})
        return
    typer.echo(f"wrote {out}: {world.name}, {segments['left']} segments left, {segments['right']} right")


def _span(interval: Interval) -> str:
    return f"{interval[0]:g}..{interval[1]:g}"


def _print_segments(world: World, description: str) -> None:
    """Each listed segment: its ends [l0], inclination and friction, one line each."""
    typer.echo(f"world {world.name or '(unnamed)'}, in l0" + (f": {description}" if description else ""))
    typer.echo(f"{'side':<5}  {'seg':>3}  {'x0':>8}  {'y0':>8}  {'x1':>8}  {'y1':>8}  {'beta deg':>8}  mu")
    for name in SIDES:
        side = world.side(name)
        betas = np.degrees(inclinations(side.points, name))
        for index in range(side.segments):
            (xa, ya), (xb, yb) = side.points[index], side.points[index + 1]
            typer.echo(
                f"{name:<5}  {index:>3}  {xa:>8.4f}  {ya:>8.4f}  {xb:>8.4f}  {yb:>8.4f}  {betas[index]:>+8.2f}  "
                + _friction(side.mu[index])
            )
    typer.echo("Below its first point and above its last, each side goes on as a vertical wall with the model's mu.")


def _friction(value: float) -> str:
    if math.isnan(value):
        return "model's"
    return "inf (no slip)" if math.isinf(value) else f"{value:g}"
