"""Imports flow one way (style.md): sim_core <- experiments <- backend <- frontend <- cli, and sim_core
stays free of web, database and plotting code. Checked with import-linter's contracts in
pyproject.toml."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_hold():
    lint_imports = Path(sys.executable).with_name("lint-imports")
    result = subprocess.run([str(lint_imports)], cwd=ROOT, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stdout + result.stderr
