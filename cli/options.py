"""What every ``parkour`` command shares: model options, controls, errors and JSON output.

Model options (``--preset`` and nondimensional overrides) are added to a command by
:func:`with_model`, which hands the command a :class:`ModelSetup`. Errors the user can fix
become one line on stderr and exit code 2 (:func:`handles_errors`).
"""

from __future__ import annotations

import functools
import inspect
import json
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import Annotated

import typer
from rich.console import Console
from rich.progress import Progress, TimeElapsedColumn

from experiments.manifest import json_safe
from sim_core import (
    ControlSchedule,
    FixedPointNotFound,
    ModelParams,
    ParameterError,
    PhysicalParams,
    get_preset,
)
from sim_core.presets import DEFAULT_PRESET

EXIT_USAGE = 2

ControlsOption = Annotated[
    str,
    typer.Option(
        "--controls",
        help="Cyclic control schedule PSI0:ZETA0[,PSI0:ZETA0...], psi0 in degrees, zeta0 in (0, 1). "
        "One pair = symmetric; two = L,R alternating.",
    ),
]
JsonOption = Annotated[bool, typer.Option("--json", help="Print machine-readable JSON.")]


@dataclass(frozen=True)
class ModelSetup:
    """The model a command runs: nondimensional parameters, and the robot they describe in SI
    (the preset's mass, l0 and g with the overrides applied), for output in metres and seconds."""

    model: ModelParams
    robot: PhysicalParams


def build_setup(preset: str, **overrides: float | None) -> ModelSetup:
    """The preset's model with any non-None nondimensional override applied."""
    robot = get_preset(preset)
    chosen = {name: value for name, value in overrides.items() if value is not None}
    model = replace(robot.to_model(), **chosen)
    if chosen:
        robot = PhysicalParams.from_model(model, mass=robot.mass, leg_length=robot.leg_length, gravity=robot.gravity)
    return ModelSetup(model=model, robot=robot)


_MODEL_PARAMETERS = [
    inspect.Parameter(
        "preset",
        inspect.Parameter.KEYWORD_ONLY,
        default=DEFAULT_PRESET,
        annotation=Annotated[str, typer.Option("--preset", help="Named parameter set (docs/model.md §1).")],
    ),
    *(
        inspect.Parameter(
            name,
            inspect.Parameter.KEYWORD_ONLY,
            default=None,
            annotation=Annotated[float | None, typer.Option(flag, help=help_text, show_default=False)],
        )
        for name, flag, help_text in (
            ("alpha", "--alpha", "Override alpha = k l0/(m g), > 0."),
            ("d_hat", "--d-hat", "Override d_hat = d/l0, wall distance, > 0."),
            ("c_zeta", "--c-zeta", "Override radial damping c_zeta_hat, >= 0."),
            ("c_psi", "--c-psi", "Override pivot damping c_psi_hat, >= 0."),
            ("mu", "--mu", "Override the friction coefficient, > 0 (inf: no slip)."),
        )
    ),
]


def with_model(command: Callable) -> Callable:
    """Add ``--preset --alpha --d-hat --c-zeta --c-psi --mu`` to ``command``; it receives ``setup``."""
    signature = inspect.signature(command, eval_str=True)
    kept = [p for p in signature.parameters.values() if p.name != "setup"]

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        values = {p.name: kwargs.pop(p.name) for p in _MODEL_PARAMETERS}
        setup = build_setup(values.pop("preset"), **values)
        return command(*args, setup=setup, **kwargs)

    parameters = [*kept, *_MODEL_PARAMETERS]
    wrapper.__signature__ = signature.replace(parameters=parameters)
    wrapper.__annotations__ = {p.name: p.annotation for p in parameters}
    return wrapper


def handles_errors(command: Callable) -> Callable:
    """Turn errors the user can fix into one line on stderr and exit code 2."""

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        try:
            return command(*args, **kwargs)
        except (ParameterError, FixedPointNotFound, OSError) as error:
            typer.echo(f"error: {error}", err=True)
            raise typer.Exit(EXIT_USAGE) from None

    return wrapper


def parse_controls(text: str) -> ControlSchedule:
    """``"30:0.9,35:0.87"`` -> schedule (psi0 in degrees)."""
    pairs = []
    for item in text.split(","):
        parts = item.strip().split(":")
        try:
            if len(parts) != 2:
                raise ValueError
            pairs.append((float(parts[0]), float(parts[1])))
        except ValueError:
            raise ParameterError(
                "controls", f"expected PSI0:ZETA0[,PSI0:ZETA0...] (psi0 in degrees), got {text!r}"
            ) from None
    return ControlSchedule.from_degrees(pairs)


def print_json(payload: object) -> None:
    """JSON on stdout; NaN and infinities are not JSON, so they become null."""
    typer.echo(json.dumps(json_safe(payload)))


@contextmanager
def progress_bar(description: str) -> Iterator[Callable[..., None]]:
    """A progress bar on stderr for long work; yields the ``progress(done, total)`` callback.

    The callback also takes ``description=`` to relabel the bar. It draws only on a terminal,
    so piped ``--json`` output and logs stay clean.
    """
    console = Console(stderr=True)
    columns = (*Progress.get_default_columns(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True, disable=not console.is_terminal) as progress:
        task = progress.add_task(description, total=None)

        def update(done: int, total: int, description: str | None = None) -> None:
            progress.update(task, completed=done, total=total, **({"description": description} if description else {}))

        yield update


def note(message: str) -> None:
    """Progress and side information for people: stderr, so stdout stays parseable."""
    print(message, file=sys.stderr)
