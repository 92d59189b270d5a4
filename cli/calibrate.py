"""``parkour calibrate``: fit the model to stored robot runs and keep it as a named preset."""

from __future__ import annotations

import math
from typing import Annotated

import typer

from cli.options import DataDirOption, JsonOption, handles_errors, note, print_json, store_sessions
from sim_core.model.errors import ParameterError
from sim_core.model.presets import DEFAULT_PRESET

app = typer.Typer(rich_markup_mode=None)


def parse_run_ids(text: str) -> list[int]:
    """``"3,4,7"`` -> [3, 4, 7]; a :class:`ParameterError` naming ``runs`` otherwise."""
    try:
        ids = [int(item) for item in text.split(",") if item.strip()]
    except ValueError:
        raise ParameterError("runs", f"expected run ids ID[,ID...], got {text!r}") from None
    if not ids or any(run_id < 1 for run_id in ids):
        raise ParameterError("runs", f"expected run ids >= 1 as ID[,ID...], got {text!r}")
    return list(dict.fromkeys(ids))


@app.command("calibrate")
@handles_errors
def calibrate_command(
    runs: Annotated[str, typer.Option("--runs", help="Robot or replay runs to fit: ID[,ID...].")],
    data_dir: DataDirOption = None,
    name: Annotated[
        str | None,
        typer.Option("--name", help="Name of the preset to store (default: calibrated-<run ids>)."),
    ] = None,
    base: Annotated[
        str, typer.Option("--preset", help="Built-in preset to start from; its d_hat, mu, mass, l0 and g are kept.")
    ] = DEFAULT_PRESET,
    json_output: JsonOption = False,
) -> None:
    """Fit alpha, c_zeta, c_psi and each leg's psi0/zeta0 offsets to robot runs (docs/calibration.md).

    The fit is stored as a preset every command accepts (--preset NAME), with the runs, date and
    code version it came from.
    """
    from backend.errors import Conflict, NotFound
    from backend.services.calibrations import calibrate_runs

    run_ids = parse_run_ids(runs)
    name = name or "calibrated-" + "-".join(map(str, run_ids))[:50]
    with store_sessions(data_dir) as sessions, sessions() as session:
        try:
            payload = calibrate_runs(session, run_ids, name=name, base=base)
        except (NotFound, Conflict) as error:
            raise ParameterError("runs", str(error)) from None
    if json_output:
        print_json(payload)
        return
    _print_report(payload)


def _print_report(payload: dict) -> None:
    params, stderr = payload["params"], payload["stderr"]
    rows = [("alpha", params["alpha"], stderr["alpha"], ""), ("c_zeta", params["c_zeta"], stderr["c_zeta"], ""),
            ("c_psi", params["c_psi"], stderr["c_psi"], "")]  # fmt: skip
    for index, side in enumerate(("left", "right")):
        rows.append((f"psi0 offset {side}", params["psi0_offset_deg"][index], stderr["psi0_offset_deg"][index], "deg"))
        rows.append((f"zeta0 offset {side}", params["zeta0_offset"][index], stderr["zeta0_offset"][index], "l0"))
    for label, value, error, unit in rows:
        spread = "not identifiable" if error is None or not math.isfinite(error) else f"± {error:.3g}"
        typer.echo(f"{label:<18} {value:>10.5g} {spread:<18} {unit}")
    typer.echo(
        f"touchdown pairs: {payload['touchdowns_used']}   one-jump state error [sqrt(g l0)]: "
        f"{payload['rms_residual_before']:.4g} (base) -> {payload['rms_residual_after']:.4g} (fitted)"
    )
    if payload["unidentifiable"]:
        note(f"the runs cannot tell these apart: {', '.join(payload['unidentifiable'])} (vary the controls more)")
    note(f"stored as preset {payload['preset']['name']!r}: use --preset {payload['preset']['name']}")


@app.command("robustness")
@handles_errors
def robustness_command(
    preset: Annotated[str, typer.Option("--preset", help="A stored calibration (parkour calibrate).")],
    runs: Annotated[
        str | None, typer.Option("--runs", help="Robot runs to compare with, ID[,ID...]; default: the preset's.")
    ] = None,
    trials: Annotated[int, typer.Option("--trials", help="MJTF trials of the model per gait.", min=1)] = 500,
    cap: Annotated[int, typer.Option("--cap", help="Jumps a trial may reach at most.", min=1)] = 2000,
    seed: Annotated[int, typer.Option("--seed", help="Seed >= 0 of the trials.", min=0)] = 0,
    data_dir: DataDirOption = None,
    json_output: JsonOption = False,
) -> None:
    """The calibrated model's Mean Jumps To Failure beside the robot's, per gait, with 95% intervals.

    The model simulates with the noise the calibration estimated from the runs (docs/calibration.md).
    """
    from backend.errors import Conflict, NotFound
    from backend.services.robustness import robustness

    run_ids = None if runs is None else parse_run_ids(runs)
    with store_sessions(data_dir) as sessions, sessions() as session:
        try:
            payload = robustness(session, preset, run_ids, trials=trials, cap=cap, seed=seed)
        except (NotFound, Conflict) as error:
            raise ParameterError(
                "preset" if isinstance(error, NotFound) and run_ids is None else "runs", str(error)
            ) from None
    if json_output:
        print_json(payload)
        return
    for row in payload["gaits"]:
        legs = ", ".join(f"{psi0:g}°:{zeta0:g}" for psi0, zeta0 in row["controls"])
        typer.echo(f"{legs:<22} robot {_mjtf_text(row['robot'])}   model {_mjtf_text(row['model'])}")


def _mjtf_text(estimate: dict) -> str:
    low, high = estimate["ci95"]
    if estimate["mjtf"] is None:
        return f"no failure in {estimate['jumps']} jumps (MJTF > {low:.0f})"
    return f"{estimate['mjtf']:.0f} [{low:.0f}, {high:.0f}] ({estimate['failures']} falls in {estimate['tries']})"
