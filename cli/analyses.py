"""``parkour basin``, ``sweep``, ``mjtf``, ``pid`` and ``atlas``: the lab's studies (issue 4)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Annotated

import numpy as np
import typer
from rich.console import Console
from rich.table import Table

from cli.options import (
    ControlsOption,
    JsonOption,
    ModelSetup,
    handles_errors,
    note,
    parse_controls,
    print_json,
    progress_bar,
    with_model,
)
from experiments.atlas_map import save_atlas
from experiments.cluster import SCHEDULER_ENV, chunk_map_for, scheduler_address
from sim_core import ControlSchedule, LegControl, ParameterError
from sim_core.atlas import gait_atlas
from sim_core.basin import DEFAULT_JUMPS, DEFAULT_TOLERANCE, BasinGrid, check_convergence_test, compute_basin
from sim_core.closed_loop import closed_loop_climb
from sim_core.height_controller import HeightController
from sim_core.mjtf import CAPPED, check_trials, mjtf_study
from sim_core.noise import NO_NOISE, NoiseModel
from sim_core.poincare import check_jumps
from sim_core.sweep import DEFAULT_BASIN_WINDOW, energy_sweep, find_in_place_zeta0, zeta0_values
from sim_core.validation import check_range

app = typer.Typer(rich_markup_mode=None)

SchedulerOption = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help=f"Dask scheduler (tcp://host:8786) to run on a cluster; default ${SCHEDULER_ENV}, else in-process.",
    ),
]

PeriodOption = Annotated[
    int | None, typer.Option("--period", help="Period n of the gait in jumps; a multiple of the schedule length.")
]
GuessOption = Annotated[
    tuple[float, float] | None,
    typer.Option("--guess", help="Initial guess XDOT YDOT for the gait; default: the most stable one a search finds."),
]


@app.command("basin")
@handles_errors
@with_model
def basin_command(
    setup: ModelSetup,
    controls: ControlsOption = "30:0.9",
    period: PeriodOption = None,
    guess: GuessOption = None,
    grid: Annotated[int, typer.Option("--grid", help="Cells per axis.")] = 100,
    jumps: Annotated[int, typer.Option("--jumps", help="Jumps allowed to converge.")] = DEFAULT_JUMPS,
    xdot_range: Annotated[
        tuple[float, float] | None,
        typer.Option("--xdot-range", help="LOW HIGH of xdot [sqrt(g l0)], below 0; default: gait ±1.5."),
    ] = None,
    ydot_range: Annotated[
        tuple[float, float] | None,
        typer.Option("--ydot-range", help="LOW HIGH of ydot [sqrt(g l0)]; default: gait ±1.5."),
    ] = None,
    tolerance: Annotated[
        float, typer.Option("--tolerance", help="Distance to the gait's orbit that counts as converged.")
    ] = DEFAULT_TOLERANCE,
    summary: Annotated[bool, typer.Option("--summary", help="With --json: leave out the per-cell grids.")] = False,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Basin of attraction of a gait over a grid of section states (xdot, ydot)."""
    from sim_core.fixed_points import gait_of

    schedule = parse_controls(controls)
    period = period or len(schedule)
    # The whole spec is checked before the (slow) gait search; placeholders stand in for default ranges.
    BasinGrid(xdot_range or (-2.0, -1.0), ydot_range or (-1.0, 1.0), grid)
    check_convergence_test(jumps, tolerance)
    with chunk_map_for(scheduler_address(scheduler)) as chunk_map:
        gait = gait_of(setup.model, schedule, period, guess)
        default = BasinGrid.around(gait.state, grid)
        cells = BasinGrid(xdot_range or default.xdot_range, ydot_range or default.ydot_range, grid)
        with progress_bar(f"basin: {grid}x{grid} cells") as progress:
            basin = compute_basin(
                setup.model,
                schedule,
                gait,
                cells,
                max_jumps=jumps,
                tolerance=tolerance,
                chunk_map=chunk_map,
                progress=progress,
            )
    if as_json:
        print_json(basin.to_dict(include_grids=not summary))
        return
    table = Table("measure", "value", title=f"Basin of the period-{gait.period} gait, controls {controls}")
    table.add_row("gait state", f"({gait.state[0]:.5f}, {gait.state[1]:.5f}), max |λ| {gait.max_abs_eigenvalue:.4f}")
    table.add_row("xdot range", f"{cells.xdot_range[0]:.3f} … {cells.xdot_range[1]:.3f}")
    table.add_row("ydot range", f"{cells.ydot_range[0]:.3f} … {cells.ydot_range[1]:.3f}")
    table.add_row("grid", f"{grid} x {grid}, {jumps} jumps, tolerance {tolerance:g}")
    table.add_row("area (g l0)", f"{basin.area:.4f} ({basin.fraction:.1%} of the window)")
    for outcome, count in basin.outcome_counts().items():
        if count:
            table.add_row(f"  {outcome}", f"{count:,} cells")
    Console().print(table)


@app.command("sweep")
@handles_errors
@with_model
def sweep_command(
    setup: ModelSetup,
    psi0: Annotated[float, typer.Option("--psi0", help="Angle of the swept leg(s) [degrees].")] = 30.0,
    zeta0_range: Annotated[
        tuple[float, float], typer.Option("--zeta0-range", help="LOW HIGH of the swept zeta0, in (0, 1).")
    ] = (0.80, 0.97),
    steps: Annotated[int, typer.Option("--steps", help="Number of zeta0 values.")] = 30,
    fixed_leg: Annotated[
        str | None,
        typer.Option("--fixed-leg", help="PSI0:ZETA0 of a leg held fixed (L); the other (R) sweeps. Default: both."),
    ] = None,
    guess: GuessOption = None,
    basin_grid: Annotated[
        int, typer.Option("--basin-grid", help="Cells per axis of each basin; 0 skips the basins.")
    ] = 40,
    basin_jumps: Annotated[int, typer.Option("--basin-jumps", help="Jumps allowed to converge.")] = DEFAULT_JUMPS,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Follow a gait over zeta0: max |λ|, climb, basin area, and the zeta0 of jumping in place."""
    zeta0s = zeta0_values(*zeta0_range, steps)
    fixed = _fixed_leg(fixed_leg)
    grid = None if basin_grid == 0 else BasinGrid(*DEFAULT_BASIN_WINDOW, basin_grid)
    check_convergence_test(basin_jumps, DEFAULT_TOLERANCE)
    sweep = _over_zeta0(
        energy_sweep,
        f"sweeping {steps} zeta0 values",
        scheduler,
        setup,
        psi0,
        zeta0s,
        fixed,
        guess,
        basin_grid=grid,
        basin_jumps=basin_jumps,
    )
    if as_json:
        print_json(sweep.to_dict())
        return
    legs = f"psi0 {psi0:g}°" + ("" if fixed is None else f", fixed leg {fixed_leg}")
    table = Table("zeta0", "energy (m g l0)", "max |λ|", "stable", "climb/jump (l0)", "basin (g l0)", title=legs)
    for point in sweep.points:
        gait = point.gait
        if gait is None:
            table.add_row(f"{point.zeta0:.4f}", f"{point.energy:.3f}", "no gait found", "", "", "")
            continue
        table.add_row(
            f"{point.zeta0:.4f}",
            f"{point.energy:.3f}",
            f"{gait.max_abs_eigenvalue:.4f}",
            "yes" if gait.stable else "no",
            f"{point.climb_per_jump:+.4f}",
            "" if point.basin_area is None else f"{point.basin_area:.3f}",
        )
    Console().print(table)
    crossings = ", ".join(f"{z:.6f}" for z in sweep.in_place_zeta0) or "none in range"
    typer.echo(f"jumping in place at zeta0 = {crossings}")


_DEFAULT_NOISE = NoiseModel()
NoisePsi0 = Annotated[float, typer.Option("--noise-psi0", help="Per-jump sigma of psi0 [deg].")]
NoiseZeta0 = Annotated[float, typer.Option("--noise-zeta0", help="Per-jump sigma of zeta0.")]
NoiseVelocity = Annotated[float, typer.Option("--noise-velocity", help="Per-jump sigma of xdot, ydot [sqrt(g l0)].")]
PitchDrift = Annotated[float, typer.Option("--pitch-drift", help="Sigma of the pitch random walk per jump [deg].")]
AsymPsi0 = Annotated[float, typer.Option("--asymmetry-psi0", help="Right leg's psi0 offset [deg].")]
AsymZeta0 = Annotated[float, typer.Option("--asymmetry-zeta0", help="Right leg's zeta0 offset.")]
SeedOption = Annotated[int, typer.Option("--seed", help="Seed >= 0; the same seed gives the same numbers.")]


# Typer reads options from each signature: mjtf's and pid's (noise) and sweep's look alike in shape
# but carry their own help and defaults; the shared ones are the aliases above.
@app.command("mjtf")
@handles_errors
@with_model
def mjtf_command(
    setup: ModelSetup,
    psi0: Annotated[float, typer.Option("--psi0", help="Leg angle [degrees].")] = 30.0,
    zeta0_range: Annotated[
        tuple[float, float], typer.Option("--zeta0-range", help="LOW HIGH of zeta0 over the energy levels.")
    ] = (0.84, 0.96),
    levels: Annotated[int, typer.Option("--levels", help="Number of energy levels.")] = 10,
    trials: Annotated[int, typer.Option("--trials", help="Trials per level.")] = 8,
    cap: Annotated[int, typer.Option("--cap", help="Jumps after which a trial counts as survived.")] = 1000,
    seed: SeedOption = 0,
    fixed_leg: Annotated[
        str | None, typer.Option("--fixed-leg", help="PSI0:ZETA0 of a leg held fixed; the other sweeps.")
    ] = None,
    guess: GuessOption = None,
    noise_psi0: NoisePsi0 = _DEFAULT_NOISE.psi0_deg,
    noise_zeta0: NoiseZeta0 = _DEFAULT_NOISE.zeta0,
    noise_velocity: NoiseVelocity = _DEFAULT_NOISE.velocity,
    pitch_drift: PitchDrift = _DEFAULT_NOISE.pitch_drift_deg,
    asymmetry_psi0: AsymPsi0 = 0.0,
    asymmetry_zeta0: AsymZeta0 = 0.0,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Mean Jumps To Failure under noise, per energy level (zeta0)."""
    noise = NoiseModel(noise_psi0, noise_zeta0, noise_velocity, pitch_drift, asymmetry_psi0, asymmetry_zeta0)
    zeta0s = zeta0_values(*zeta0_range, levels)
    check_trials(trials, cap)
    study = _over_zeta0(
        mjtf_study,
        f"MJTF: {levels} levels x {trials} trials",
        scheduler,
        setup,
        psi0,
        zeta0s,
        _fixed_leg(fixed_leg),
        guess,
        noise=noise,
        trials=trials,
        cap=cap,
        seed=seed,
    )
    if as_json:
        print_json(study.to_dict())
        return
    table = Table("zeta0", "E (m g l0)", "MJTF", "std", "95% CI", "capped", "failures", title=f"psi0 {psi0:g}°")
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


@app.command("pid")
@handles_errors
@with_model
def pid_command(
    setup: ModelSetup,
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
    noise_psi0: NoisePsi0 = _DEFAULT_NOISE.psi0_deg,
    noise_zeta0: NoiseZeta0 = _DEFAULT_NOISE.zeta0,
    noise_velocity: NoiseVelocity = _DEFAULT_NOISE.velocity,
    pitch_drift: PitchDrift = _DEFAULT_NOISE.pitch_drift_deg,
    asymmetry_psi0: AsymPsi0 = 0.0,
    asymmetry_zeta0: AsymZeta0 = 0.0,
    as_json: JsonOption = False,
) -> None:
    """Closed-loop climb to a target height: a PID on the touchdown height sets the next zeta0."""
    from sim_core.fixed_points import gait_of
    from sim_core.presets import START_GUESS

    noise = NoiseModel(noise_psi0, noise_zeta0, noise_velocity, pitch_drift, asymmetry_psi0, asymmetry_zeta0)
    scales = setup.robot.scales
    target_l0 = check_range("target", target, 0.0, 1e3) / scales.length
    leg = LegControl.from_degrees(psi0, start_zeta0)
    HeightController(target_l0, (zeta0_min + zeta0_max) / 2, kp, ki, kd, zeta0_min, zeta0_max)  # check first
    check_jumps(jumps)
    hover = find_in_place_zeta0(setup.model, leg.psi0, zeta0_range=(zeta0_min, zeta0_max))
    controller = HeightController(target_l0, hover, kp, ki, kd, zeta0_min, zeta0_max)
    start = gait_of(setup.model, ControlSchedule.of(leg), guess=START_GUESS).state
    run = closed_loop_climb(
        setup.model,
        controller,
        leg.psi0,
        start,
        jumps,
        start_zeta0=start_zeta0,
        noise=noise if noisy else NO_NOISE,
        seed=seed,
    )
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


def _run_study(study: Callable, description: str, scheduler: str | None, *args, **kwargs):
    """``study(*args, **kwargs, chunk_map=..., progress=...)``: on the Dask cluster ``scheduler``
    names (else in-process), with a progress bar labelled ``description``."""
    with (
        chunk_map_for(scheduler_address(scheduler)) as chunk_map,
        progress_bar(description) as progress,
    ):
        return study(*args, chunk_map=chunk_map, progress=progress, **kwargs)


def _over_zeta0(
    study: Callable,
    description: str,
    scheduler,
    setup: ModelSetup,
    psi0_deg: float,
    zeta0s,
    fixed_leg,
    guess,
    **options,
):
    """A study of the gait over zeta0 values (sweep, MJTF): ``study(model, psi0 [rad], zeta0s, ...)``
    with one leg ``fixed_leg`` held (None: both legs swept) and the first gait from ``guess``."""
    psi0 = LegControl.from_degrees(psi0_deg, zeta0s[0]).psi0
    return _run_study(
        study, description, scheduler, setup.model, psi0, zeta0s, fixed_leg=fixed_leg, guess=guess, **options
    )


def _fixed_leg(text: str | None) -> LegControl | None:
    if text is None:
        return None
    schedule = parse_controls(text)
    if len(schedule) != 1:
        raise ParameterError("fixed_leg", f"must be one PSI0:ZETA0 pair, got {text!r}")
    return schedule[0]


@app.command("atlas")
@handles_errors
@with_model
def atlas_command(
    setup: ModelSetup,
    psi0_range: Annotated[
        tuple[float, float], typer.Option("--psi0-range", help="LOW HIGH of psi0 [degrees] (symmetric atlas).")
    ] = (15.0, 45.0),
    zeta0_range: Annotated[tuple[float, float], typer.Option("--zeta0-range", help="LOW HIGH of zeta0.")] = (
        0.80,
        0.98,
    ),
    grid: Annotated[tuple[int, int], typer.Option("--grid", help="ROWS COLUMNS of the atlas.")] = (13, 19),
    pair: Annotated[
        tuple[float, float] | None,
        typer.Option(
            "--pair", help="PSI0_L PSI0_R [degrees]: an L/R atlas over zeta0_L (rows) x zeta0_R (columns) instead."
        ),
    ] = None,
    transient: Annotated[int, typer.Option("--transient", help="Jumps to let each orbit settle.")] = 300,
    plot: Annotated[Path | None, typer.Option("--plot", help="Also draw the map to this .png or .svg file.")] = None,
    scheduler: SchedulerOption = None,
    as_json: JsonOption = False,
) -> None:
    """Where stable gaits live over a grid of controls: period and climb of the most stable gait."""
    rows_count, columns_count = grid
    if plot is not None and plot.suffix not in (".png", ".svg"):
        raise ParameterError("plot", f"must end in .png or .svg, got {plot.name!r}")
    columns = zeta0_values(*zeta0_range, columns_count)
    if pair is None:
        rows = _degrees_values("psi0_range", psi0_range, rows_count)
        schedules = [ControlSchedule.from_degrees([(psi0, zeta0)]) for psi0 in rows for zeta0 in columns]
        labels = ("psi0 [deg]", "zeta0 [l0]")
    else:
        rows = zeta0_values(*zeta0_range, rows_count)
        schedules = [
            ControlSchedule.from_degrees([(pair[0], zeta0_left), (pair[1], zeta0_right)])
            for zeta0_left in rows
            for zeta0_right in columns
        ]
        labels = (f"zeta0_L [l0] (psi0_L {pair[0]:g}°)", f"zeta0_R [l0] (psi0_R {pair[1]:g}°)")
    check_jumps(transient)
    atlas = _run_study(
        gait_atlas,
        f"atlas: {rows_count}x{columns_count} cells",
        scheduler,
        setup.model,
        schedules,
        rows,
        columns,
        row_label=labels[0],
        column_label=labels[1],
        transient_jumps=transient,
    )
    if plot is not None:
        save_atlas(atlas, plot, "Gait atlas" + ("" if pair is None else f", psi0 {pair[0]:g}°/{pair[1]:g}°"))
        note(f"atlas map: {plot}")
    if as_json:
        print_json(atlas.to_dict())
        return
    counts = atlas.count
    climbing = np.nansum(atlas.climb_per_jump > 0)
    typer.echo(
        f"{counts.size} cells: {int(np.count_nonzero(counts))} with a stable gait, {int(climbing)} climbing; "
        f"periods found: {sorted(set(atlas.period[counts > 0].tolist())) or 'none'}"
    )


def _degrees_values(field: str, interval: tuple[float, float], count: int) -> np.ndarray:
    low, high = (check_range(field, value, 0.0, 90.0) for value in interval)
    if not low < high or not 2 <= count <= 1000:
        raise ParameterError(field, f"needs low < high and 2 to 1000 values, got [{low:g}, {high:g}] x {count}")
    return np.linspace(low, high, count)
