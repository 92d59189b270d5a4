"""What every ``parkour`` command shares: options, controls, errors and JSON output.

Model options (``--preset`` and nondimensional overrides) are added to a command by
:func:`with_model`, which hands the command a :class:`ModelSetup`; noise options by
:func:`with_noise`, which hands it a :class:`~sim_core.model.noise.NoiseModel`. Errors the user can fix
become one line on stderr and exit code 2 (:func:`handles_errors`).

Light by design: this module and the command modules import typer and the light parts of
``sim_core`` (parameters, controls, presets, errors) only; a command imports the kernels, the
store or the service when it runs, so ``parkour --help`` starts at once (tests/cli/test_startup.py).
"""

from __future__ import annotations

import functools
import inspect
import json
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Annotated

import typer

from experiments.cluster import SCHEDULER_ENV
from experiments.manifest import json_safe
from sim_core.model.controls import ControlSchedule
from sim_core.model.errors import FixedPointNotFound, ParameterError
from sim_core.model.noise import NoiseModel
from sim_core.model.params import ModelParams, PhysicalParams
from sim_core.model.presets import DEFAULT_PRESET, PRESETS, get_preset

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
PeriodOption = Annotated[
    int | None,
    typer.Option("--period", help="Period n of the gait in jumps; a multiple of the schedule length (default: it)."),
]
GuessOption = Annotated[
    tuple[float, float] | None,
    typer.Option(
        "--guess",
        help="Initial guess XDOT YDOT for the gait (Levenberg–Marquardt); default: the most stable one a grid "
        "search finds.",
    ),
]
SchedulerOption = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help=f"Dask scheduler (tcp://host:8786) to run on a cluster; default ${SCHEDULER_ENV}, else in-process.",
    ),
]
SeedOption = Annotated[int, typer.Option("--seed", help="Seed >= 0; the same seed gives the same numbers.")]
DataDirOption = Annotated[
    Path | None,
    typer.Option("--data-dir", help="Where the database and token live; default $PARKOUR_DATA_DIR or ./data."),
]


@dataclass(frozen=True)
class ModelSetup:
    """The model a command runs: nondimensional parameters, and the robot they describe in SI
    (the preset's mass, l0 and g with the overrides applied), for output in metres and seconds."""

    model: ModelParams
    robot: PhysicalParams


def build_setup(preset: str, **overrides: float | None) -> ModelSetup:
    """The preset's model with any non-None nondimensional override applied; the preset resolved
    as every caller resolves one (:func:`backend.services.presets.resolve_model`)."""
    from backend.services.presets import resolve_model  # light: it loads the store only for a stored preset

    robot = resolve_model(None, preset).robot if preset in PRESETS else stored_preset(preset)
    chosen = {name: value for name, value in overrides.items() if value is not None}
    model = replace(robot.to_model(), **chosen)
    if chosen:
        robot = PhysicalParams.from_model(model, mass=robot.mass, leg_length=robot.leg_length, gravity=robot.gravity)
    return ModelSetup(model=model, robot=robot)


def stored_preset(name: str) -> PhysicalParams:
    """A preset ``parkour calibrate`` stored, from the database of ``$PARKOUR_DATA_DIR`` (default
    ./data) or ``$DATABASE_URL``; the unknown-preset error if there is none (no store is created)."""
    from backend.services.presets import resolve_model

    try:
        with store_sessions(None) as sessions, sessions() as session:
            return resolve_model(session, name).robot
    except ParameterError as error:
        if error.field != "data_dir":
            raise
        return get_preset(name)  # no store: raises, naming the built-in presets


@contextmanager
def store_sessions(data_dir: Path | None) -> Iterator[Callable]:
    """Sessions on the store of ``data_dir`` (default ``$PARKOUR_DATA_DIR`` or ./data; ``$DATABASE_URL``
    wins), migrated as the service's start migrates it. A SQLite store that does not exist is a
    :class:`ParameterError` naming ``data_dir``: a command that reads never creates an empty one."""
    from backend.settings import Settings
    from backend.store.database import opened_store, sqlite_file

    settings = Settings.from_environment(data_dir)
    database = sqlite_file(settings.database_url)
    if database is not None and not database.exists():
        raise ParameterError("data_dir", f"no store in {settings.data_dir} (no {database.name}); give --data-dir")
    with opened_store(settings.database_url) as sessions:
        yield sessions


_MODEL_PARAMETERS = [
    inspect.Parameter(
        "preset",
        inspect.Parameter.KEYWORD_ONLY,
        default=DEFAULT_PRESET,
        annotation=Annotated[
            str,
            typer.Option("--preset", help="Named parameter set (docs/model.md §1), or one parkour calibrate stored."),
        ],
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
    return _with_options(command, "setup", _MODEL_PARAMETERS, build_setup)


_DEFAULT_NOISE = NoiseModel()
_NOISE_OPTIONS = (  # parameter, NoiseModel field, flag, help
    ("noise_psi0", "psi0_deg", "--noise-psi0", "Per-jump sigma of psi0 [deg]."),
    ("noise_zeta0", "zeta0", "--noise-zeta0", "Per-jump sigma of zeta0."),
    ("noise_velocity", "velocity", "--noise-velocity", "Per-jump sigma of xdot, ydot [sqrt(g l0)]."),
    ("pitch_drift", "pitch_drift_deg", "--pitch-drift", "Sigma of the pitch random walk per jump [deg]."),
    ("asymmetry_psi0", "asymmetry_psi0_deg", "--asymmetry-psi0", "Right leg's psi0 offset [deg]."),
    ("asymmetry_zeta0", "asymmetry_zeta0", "--asymmetry-zeta0", "Right leg's zeta0 offset."),
)
_NOISE_PARAMETERS = [
    inspect.Parameter(
        name,
        inspect.Parameter.KEYWORD_ONLY,
        default=getattr(_DEFAULT_NOISE, field),
        annotation=Annotated[float, typer.Option(flag, help=help_text)],
    )
    for name, field, flag, help_text in _NOISE_OPTIONS
]


def with_noise(command: Callable) -> Callable:
    """Add the noise model's options (``--noise-psi0 ... --asymmetry-zeta0``, docs/model.md §5.1) to
    ``command``; it receives ``noise``, a :class:`~sim_core.model.noise.NoiseModel`."""

    def build(**values: float) -> NoiseModel:
        return NoiseModel(**{field: values[name] for name, field, _flag, _help in _NOISE_OPTIONS})

    return _with_options(command, "noise", _NOISE_PARAMETERS, build)


def _with_options(command: Callable, name: str, options: list[inspect.Parameter], build: Callable) -> Callable:
    """``command`` with its parameter ``name`` replaced by ``options``, from which ``build`` makes it."""
    signature = inspect.signature(command, eval_str=True)
    kept = [p for p in signature.parameters.values() if p.name != name]

    @functools.wraps(command)
    def wrapper(*args, **kwargs):
        values = {p.name: kwargs.pop(p.name) for p in options}
        return command(*args, **{name: build(**values)}, **kwargs)

    parameters = [*kept, *options]
    wrapper.__signature__ = signature.replace(parameters=parameters)
    wrapper.__annotations__ = {p.name: p.annotation for p in parameters}
    return wrapper


@contextmanager
def option_named(option: str, *fields: str) -> Iterator[None]:
    """A ParameterError about one of ``fields`` (a library's name for it) said about the user's
    ``option`` instead: ``parkour mjtf --levels 1`` is told "--levels: must be …", not "steps:
    …", which names no option of the command."""
    try:
        yield
    except ParameterError as error:
        if error.field not in fields:
            raise
        raise ParameterError(option, error.message) from None


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
    from rich.console import Console
    from rich.progress import Progress, TimeElapsedColumn

    console = Console(stderr=True)
    columns = (*Progress.get_default_columns(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True, disable=not console.is_terminal) as progress:
        task = progress.add_task(description, total=None)

        def update(done: int, total: int, description: str | None = None) -> None:
            progress.update(task, completed=done, total=total, **({"description": description} if description else {}))

        yield update


def refuse_given(options: dict, why: str) -> None:
    """A ParameterError naming the first of ``options`` (option -> value) given (not None), saying ``why``."""
    for option, value in options.items():
        if value is not None:
            raise ParameterError(option, why)


def note(message: str) -> None:
    """Progress and side information for people: stderr, so stdout stays parseable."""
    print(message, file=sys.stderr)
