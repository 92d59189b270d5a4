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


def one_line_error(*args: str) -> str:
    """The command's refusal, after checking it is one line on stderr and exit code 2."""
    result = invoke(*args)
    assert result.exit_code == 2, result.output
    assert result.stderr.startswith("error: ") and len(result.stderr.strip().splitlines()) == 1, result.stderr
    return result.stderr.strip()
