"""``parkour viability``: the viability kernel and its measure over section state x leg controls."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import JsonOption, ModelSetup, handles_errors, option_named, print_json, progress_bar, with_model
from sim_core.viability.grid import (
    DEFAULT_ACTIONS,
    DEFAULT_PSI0_DEG,
    DEFAULT_STATES,
    DEFAULT_XDOT,
    DEFAULT_YDOT,
    DEFAULT_ZETA0,
)

app = typer.Typer(rich_markup_mode=None)
Interval = tuple[float, float]


@app.command("viability")
@handles_errors
@with_model
def viability_command(
    setup: ModelSetup,
    states: Annotated[int, typer.Option("--states", help="Nodes per velocity axis (xdot, ydot).")] = DEFAULT_STATES,
    actions: Annotated[int, typer.Option("--actions", help="Nodes per control axis (psi0, zeta0).")] = DEFAULT_ACTIONS,
    xdot_range: Annotated[
        Interval, typer.Option("--xdot-range", help="Mid-chute xdot LOW HIGH [sqrt(g l0)], toward the wall.")
    ] = DEFAULT_XDOT,
    ydot_range: Annotated[Interval, typer.Option("--ydot-range", help="Mid-chute ydot LOW HIGH.")] = DEFAULT_YDOT,
    psi0_range: Annotated[Interval, typer.Option("--psi0-range", help="Leg angle LOW HIGH [deg].")] = DEFAULT_PSI0_DEG,
    zeta0_range: Annotated[Interval, typer.Option("--zeta0-range", help="Leg length LOW HIGH [l0].")] = DEFAULT_ZETA0,
    pitch_nodes: Annotated[
        int, typer.Option("--pitch-nodes", help="Nodes of a pitch axis (0: none; odd puts one at zero).")
    ] = 0,
    pitch_deg: Annotated[float, typer.Option("--pitch-deg", help="The pitch axis spans +-this [deg].")] = 0.0,
    state: Annotated[
        tuple[float, float] | None,
        typer.Option("--state", help="Also list the viable actions at the node nearest XDOT YDOT (pitch 0)."),
    ] = None,
    world: Annotated[
        str | None,
        typer.Option("--world", help="In this world (a file or a named world): centre-line states, with height."),
    ] = None,
    heights: Annotated[int, typer.Option("--heights", help="With --world: nodes of the height axis.")] = 12,
    as_json: JsonOption = False,
) -> None:
    """The states from which some leg command keeps the robot jumping forever, and how many do.

    With --world (docs/worlds.md), the state is the body crossing the chute's centre line: height,
    xdot (its sign: the side it flies toward) and ydot; a climb also fails at the floor."""
    import numpy as np

    from sim_core.viability.engine import compute_viability
    from sim_core.viability.grid import degrees_of, section_grid
    from sim_core.viability.step_map import section_step_map

    if world is not None:
        _world_viability(setup, world, heights, states, actions, xdot_range, ydot_range, psi0_range, zeta0_range,
                         pitch_nodes, state, as_json)  # fmt: skip
        return
    with (
        option_named("--states", "states"),
        option_named("--actions", "actions"),
        option_named("--xdot-range", "xdot_range"),
        option_named("--ydot-range", "ydot_range"),
        option_named("--psi0-range", "psi0_range"),
        option_named("--zeta0-range", "zeta0_range"),
        option_named("--pitch-nodes", "pitch_nodes"),
        option_named("--pitch-deg", "pitch_deg"),
        option_named("--states", "grid"),
    ):
        grid = section_grid(
            states=states,
            actions=actions,
            xdot_range=xdot_range,
            ydot_range=ydot_range,
            psi0_deg_range=psi0_range,
            zeta0_range=zeta0_range,
            pitch_nodes=pitch_nodes,
            pitch_deg=pitch_deg,
        )
    step_map = section_step_map(setup.model, with_pitch=pitch_nodes > 0)
    with progress_bar(f"viability: {grid.pairs:,} state-action pairs") as bar:
        result = compute_viability(step_map, grid, progress=bar)
    payload = result.to_dict()
    axes = {"xdot": grid.state_axes[0].tolist(), "ydot": grid.state_axes[1].tolist()}
    if pitch_nodes:
        axes["pitch_deg"] = np.degrees(grid.state_axes[2]).tolist()
    payload["state_axes"] = axes
    psi0_axis, zeta0_axis = grid.action_axes
    payload["action_axes"] = {"psi0_deg": np.degrees(psi0_axis).tolist(), "zeta0": zeta0_axis.tolist()}
    if state is not None:
        node = result.nearest_node((*state, 0.0) if pitch_nodes else state)
        payload["state"] = {
            "requested": list(state),
            "node": [float(axis[i]) for axis, i in zip(grid.state_axes, node, strict=True)],
            "in_kernel": bool(result.kernel[node]),
            "measure": float(result.measure[node]),
            "viable_actions": degrees_of(result.viable_actions(node)).tolist(),
        }
    if as_json:
        print_json(payload)
        return
    print(
        f"viability kernel: {payload['kernel_cells']:,} of {payload['cells']:,} state nodes "
        f"({payload['kernel_fraction']:.1%}); viable pairs {payload['viable_pair_fraction']:.1%}, "
        f"mean measure in the kernel {payload['measure_mean']:.2f}; "
        f"{payload['pairs']:,} pairs in {payload['seconds']:.1f} s"
    )
    if state is not None:
        chosen = payload["state"]
        verdict = "in the kernel" if chosen["in_kernel"] else "outside the kernel"
        print(
            f"node {tuple(round(v, 3) for v in chosen['node'])}: {verdict}, measure {chosen['measure']:.2f}, "
            f"{len(chosen['viable_actions'])} viable actions"
        )


def _world_viability(setup, world, heights, states, actions, xdot_range, ydot_range, psi0_range, zeta0_range,
                     pitch_nodes, state, as_json) -> None:  # fmt: skip
    """``parkour viability --world``: the kernel over centre-line states (height, xdot, ydot)."""
    import numpy as np

    from sim_core.model.errors import ParameterError
    from sim_core.viability import world_step_map as in_world
    from sim_core.viability.engine import compute_viability
    from sim_core.world.named import resolve_world

    if pitch_nodes:
        raise ParameterError("--pitch-nodes", "a world's viability has no pitch axis; leave it 0 with --world")
    if state is not None:
        raise ParameterError("--state", "is read on parallel walls only; with --world see the JSON's kernel")
    chosen, _description = resolve_world(world, setup.model.d_hat, setup.robot.scales.length)
    states = in_world.DEFAULT_STATES if states == DEFAULT_STATES else states  # a world's own defaults
    actions = in_world.DEFAULT_ACTIONS if actions == DEFAULT_ACTIONS else actions
    with (
        option_named("--heights", "heights"),
        option_named("--states", "states", "grid"),
        option_named("--actions", "actions"),
        option_named("--xdot-range", "xdot_range"),
        option_named("--ydot-range", "ydot_range"),
        option_named("--psi0-range", "psi0_range"),
        option_named("--zeta0-range", "zeta0_range"),
    ):
        grid = in_world.world_grid(
            chosen, heights=heights, states=states, actions=actions,
            xdot_range=in_world.DEFAULT_XDOT if xdot_range == DEFAULT_XDOT else xdot_range,
            ydot_range=in_world.DEFAULT_YDOT if ydot_range == DEFAULT_YDOT else ydot_range,
            psi0_deg_range=psi0_range, zeta0_range=zeta0_range,
        )  # fmt: skip
    step_map = in_world.world_step_map(setup.model, chosen)
    with progress_bar(f"viability in {chosen.name}: {grid.pairs:,} state-action pairs") as bar:
        result = compute_viability(step_map, grid, progress=bar)
    payload = result.to_dict()
    names = ("y", "xdot", "ydot")
    payload["state_axes"] = {name: axis.tolist() for name, axis in zip(names, grid.state_axes, strict=True)}
    psi0_axis, zeta0_axis = grid.action_axes
    payload["action_axes"] = {"psi0_deg": np.degrees(psi0_axis).tolist(), "zeta0": zeta0_axis.tolist()}
    kernel_heights = grid.state_axes[0][result.kernel.any(axis=(1, 2))]
    payload["world"] = chosen.name
    payload["kernel_heights"] = kernel_heights.tolist()
    if as_json:
        print_json(payload)
        return
    print(
        f"viability in {chosen.name}: {payload['kernel_cells']:,} of {payload['cells']:,} state nodes "
        f"({payload['kernel_fraction']:.1%}); viable pairs {payload['viable_pair_fraction']:.1%}, "
        f"mean measure in the kernel {payload['measure_mean']:.2f}; heights with a viable state: "
        f"{len(kernel_heights)} of {grid.state_axes[0].size}; {payload['pairs']:,} pairs in {payload['seconds']:.1f} s"
    )
