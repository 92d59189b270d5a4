"""The shape of the tree (style.md), checked: imports flow one way (sim_core <- experiments <- backend
<- frontend <- cli, and the backend's rooms each import only the rooms below) by import-linter's
contracts in pyproject.toml; SQL is written in one room; modules stay small."""

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_hold():
    lint_imports = Path(sys.executable).with_name("lint-imports")
    result = subprocess.run([str(lint_imports)], cwd=ROOT, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stdout + result.stderr


SOURCE_ROOTS = ("sim_core", "experiments", "backend", "frontend", "cli", "parkourlab")
SQL_HOMES = ("backend/store/", "backend/repositories/")
# What a unit of work may name outside the store: the session, its factory, the errors a store raises.
SESSION_NAMES = {"sqlalchemy.orm": {"Session", "sessionmaker"}, "sqlalchemy.exc": None}
MAX_LINES, LONG_LINES, MAX_LONG_MODULES = 400, 300, 3


def _modules():
    for root in SOURCE_ROOTS:
        for path in sorted((ROOT / root).rglob("*.py")):
            relative = path.relative_to(ROOT).as_posix()
            if "/migrations/" not in relative:
                yield relative, path


def test_sql_is_written_only_in_the_store_and_its_repositories():
    """No module outside backend/store and backend/repositories builds statements (select, update,
    func …): services hold a Session, the repositories say what it runs."""
    offences = []
    for relative, path in _modules():
        if relative.startswith(SQL_HOMES):
            continue
        for node in ast.walk(ast.parse(path.read_text(), relative)):
            if isinstance(node, ast.Import):
                offences += [f"{relative}: import {a.name}" for a in node.names if a.name.split(".")[0] == "sqlalchemy"]
            elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "sqlalchemy":
                allowed = SESSION_NAMES.get(node.module, set())
                names = [a.name for a in node.names]
                if allowed is not None and not set(names) <= allowed:
                    offences.append(f"{relative}: from {node.module} import {', '.join(names)}")
    assert not offences, "\n".join(offences)


def test_modules_stay_small():
    """style.md: a module of a few hundred lines; a bigger file is two ideas. None over 400 lines and
    at most three over 300 (migrations aside)."""
    lengths = {relative: len(path.read_text().splitlines()) for relative, path in _modules()}
    too_long = {name: n for name, n in lengths.items() if n > MAX_LINES}
    long = {name: n for name, n in lengths.items() if n > LONG_LINES}
    assert not too_long, too_long
    assert len(long) <= MAX_LONG_MODULES, long
