"""The ``parkour`` command: simulate, analyse and benchmark the ParkourBot model.

Every command takes the model options ``--preset`` (default ``paper``) and the
nondimensional overrides ``--alpha --d-hat --c-zeta --c-psi --mu``; ``--json`` prints the
machine-readable form scripts rely on (keep it stable: extend, never break). Errors a user
can fix print one line and exit with code 2.

``parkour serve`` starts the service with the control panel and the 3D view; ``parkour export``
writes a stored robot or replay run as an MCAP recording; ``parkour token`` gives the lab's people
API tokens of their own; ``parkour world`` lists, shows and makes the worlds of general chutes.
"""

from __future__ import annotations

import typer

from cli import (
    atlas,
    basin,
    bench,
    calibrate,
    climb,
    control_study,
    export,
    foothold,
    gaits,
    mfpt,
    mjtf,
    pid,
    plan,
    reach,
    reproduce,
    robot,
    serve,
    simulate,
    sweep,
    token,
    viability,
    world,
)

app = typer.Typer(
    name="parkour",
    help="ParkourLab: simulate, analyse and benchmark the ParkourBot climbing robot.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)
# In the order of --help.
COMMANDS = (
    simulate,
    world,
    climb,
    reach,
    plan,
    foothold,
    gaits,
    basin,
    sweep,
    mjtf,
    mfpt,
    viability,
    pid,
    control_study,
    atlas,
    reproduce,
    robot,
    calibrate,
    export,
    bench,
    serve,
    token,
)
for command in COMMANDS:
    app.add_typer(command.app)


def main() -> None:
    app()


if __name__ == "__main__":
    main()
