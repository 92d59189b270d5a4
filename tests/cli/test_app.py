"""The ``parkour`` command (cli/app.py): one sub-app per command file, listed in the order of
``COMMANDS``; no command shows the list; an unknown one is named; ``main`` is the console script."""

from __future__ import annotations

import importlib
import pkgutil
import sys

import click
import pytest
import typer
import typer.main

import cli
from cli.app import COMMANDS, app, main
from tests.cli.helpers import invoke


def registered() -> list[str]:
    """The commands each command file defines, in the order of COMMANDS (a file that names its
    app is one command of several sub-commands: ``parkour token add|list|revoke``)."""
    names = []
    for module in COMMANDS:
        group = module.app.info.name
        names += [group] if isinstance(group, str) else [command.name for command in module.app.registered_commands]
    return names


def test_every_command_files_commands_are_listed_in_order():
    group = typer.main.get_command(app)
    assert group.list_commands(click.Context(group)) == registered()
    assert {"map", "reproduce", "robot-sim", "serve", "token"} <= set(registered())
    listed = invoke("--help").stdout
    positions = [listed.index(f"\n  {name} ") for name in registered()]
    assert positions == sorted(positions), "--help lists them in the order of COMMANDS"


def test_every_command_file_is_a_sub_app_of_parkour():
    names = [info.name for info in pkgutil.iter_modules(cli.__path__) if info.name != "__main__"]  # runs parkour
    modules = (importlib.import_module(f"cli.{name}") for name in names)
    command_files = {module for module in modules if isinstance(getattr(module, "app", None), typer.Typer)}
    assert command_files - {sys.modules["cli.app"]} == set(COMMANDS)


def test_without_a_command_it_shows_the_list():
    result = invoke()
    assert result.exit_code == 2
    assert "Usage: parkour" in result.output and all(f"  {name} " in result.output for name in registered())


def test_an_unknown_command_is_named():
    result = invoke("leap")
    assert result.exit_code == 2 and "No such command 'leap'" in result.output


def test_main_runs_the_command_line(monkeypatch, capsys):
    monkeypatch.setattr(sys, "argv", ["parkour", "map", "--state", "-0.93", "-0.17", "--jumps", "1", "--json"])
    with pytest.raises(SystemExit) as done:
        main()
    assert done.value.code in (0, None)
    assert '"states"' in capsys.readouterr().out
