"""``parkour bench``: the compiled map against the scipy baseline, side by side."""

from __future__ import annotations

from typing import Annotated

import typer

from cli.options import JsonOption, handles_errors, note, print_json

app = typer.Typer(rich_markup_mode=None)


@app.command("bench")
@handles_errors
def bench_command(
    baseline_strides: Annotated[int, typer.Option(help="Strides for the scipy baseline.", min=1)] = 200,
    kernel_strides: Annotated[int, typer.Option(help="Strides for the one-core kernel timing.", min=1)] = 20_000,
    batch_strides: Annotated[int, typer.Option(help="Strides for the all-cores batch timing.", min=1)] = 100_000,
    repeats: Annotated[int, typer.Option(help="Timings per figure; the best is kept.", min=1)] = 3,
    basin_grid: Annotated[int, typer.Option(help="Cells per axis of the timed basin.", min=2, max=2000)] = 200,
    basin_jumps: Annotated[int, typer.Option(help="Jumps per cell of the timed basin.", min=1)] = 60,
    as_json: JsonOption = False,
) -> None:
    """Strides per second of the kernel vs scipy solve_ivp (DOP853, rtol=atol=1e-10), and their difference."""
    from sim_core.bench import run_benchmark

    # A thin command: its options go to the one library call as they are (name=name, as in the API's routes).
    result = run_benchmark(
        baseline_strides=baseline_strides,
        kernel_strides=kernel_strides,
        batch_strides=batch_strides,
        repeats=repeats,
        basin_grid=basin_grid,
        basin_jumps=basin_jumps,
        progress=lambda stage: note(f"bench: {stage}…"),
    )
    if as_json:
        print_json(result.to_dict())
        return
    from rich.console import Console
    from rich.table import Table

    table = Table("measure", "value", title="parkour bench (paper preset, controls 30:0.9)")
    table.add_row("kernel, one core", f"{result.kernel_strides_per_s:,.0f} strides/s")
    table.add_row("scipy DOP853 baseline", f"{result.baseline_strides_per_s:,.0f} strides/s")
    table.add_row("ratio", f"{result.ratio:,.0f}x")
    table.add_row("largest difference", f"{result.max_abs_diff:.2e}")
    table.add_row(f"batch, {result.cores} cores", f"{result.batch_strides_per_s:,.0f} strides/s")
    table.add_row(
        f"basin {result.basin_grid}x{result.basin_grid} x {result.basin_jumps} jumps",
        f"{result.basin_seconds:.2f} s ({result.basin_jumps_computed:,} jumps)",
    )
    table.add_row(
        "  baseline, projected",
        f"{result.basin_baseline_projected_seconds:,.0f} s ({result.basin_speedup:,.0f}x slower)",
    )
    table.add_row(f"world of {result.world_segments} segments a side, one core",
                  f"{result.world_kernel_strides_per_s:,.0f} strides/s "
                  f"({result.world_cost_vs_parallel:.2f}x a parallel-walls stride's time)")  # fmt: skip
    table.add_row("  its scipy twin", f"{result.world_baseline_strides_per_s:,.0f} strides/s")
    table.add_row("  ratio, largest difference", f"{result.world_ratio:,.0f}x, {result.world_max_abs_diff:.2e}")
    Console().print(table)
