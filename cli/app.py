"""The ``parkour`` command: simulate, analyse and benchmark the ParkourBot model.

Every command takes the model options ``--preset`` (default ``paper``) and the
nondimensional overrides ``--alpha --d-hat --c-zeta --c-psi --mu``; ``--json`` prints the
machine-readable form scripts rely on (keep it stable: extend, never break). Errors a user
can fix print one line and exit with code 2.

``parkour serve`` starts the service with the control panel and the 3D view.
"""

from __future__ import annotations

import typer

from cli import analyses, bench, gaits, reproduce, robot, serve, simulate

app = typer.Typer(
    name="parkour",
    help="ParkourLab: simulate, analyse and benchmark the ParkourBot climbing robot.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)
for sub_app in (simulate.app, gaits.app, analyses.app, reproduce.app, robot.app, bench.app, serve.app):
    app.add_typer(sub_app)


def main() -> None:
    app()


if __name__ == "__main__":
    main()
