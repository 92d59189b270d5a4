"""Shared by the command tests: run ``parkour`` in-process and read its JSON."""

import json

from typer.testing import CliRunner

from cli.app import app

runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(app, list(args))


def json_of(*args: str):
    """The command's JSON on stdout, after checking it succeeded."""
    result = invoke(*args, "--json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)
