"""The ``parkour`` command: the backend's commands (simulate, analyse, robot, bench, ...) plus
``serve``, which starts the service with the control panel and the 3D view."""

from __future__ import annotations

from backend.cli.app import app
from frontend import serve

app.add_typer(serve.app)


def main() -> None:
    app()


if __name__ == "__main__":
    main()
