#!/usr/bin/env bash
# The test suite: set up .venv/ with the dev tools if needed, lint, then run every test.
# Arguments go to pytest, e.g. ./test.sh -m "not slow" or ./test.sh tests/sim_core
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$root"
scripts/ensure-venv.sh dev
.venv/bin/ruff check .
.venv/bin/ruff format --check .
exec .venv/bin/python -m pytest "$@"
