#!/usr/bin/env bash
# The test suite: set up .venv/ with the dev tools if needed, lint, then run every test.
# Arguments go to pytest, e.g. ./test.sh -m "not slow" or ./test.sh tests/sim_core
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$root"
scripts/ensure-venv.sh dev
# The browser tests drive Debian's Chromium through Playwright, and the store and API tests run on
# PostgreSQL as well as SQLite (tests/postgres.py starts a scratch server from Debian's binaries).
# Install what is missing when we can (root with apt); otherwise those tests skip and say why.
missing=()
command -v chromium >/dev/null 2>&1 || missing+=(chromium)
compgen -G "/usr/lib/postgresql/*/bin/initdb" >/dev/null || missing+=(postgresql)
if [ ${#missing[@]} -gt 0 ] && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  echo "installing ${missing[*]} for the tests (Debian packages)" >&2
  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}"; } >/dev/null 2>&1 ||
    echo "could not install ${missing[*]}: the tests that need them will be skipped" >&2
fi
.venv/bin/ruff check .
.venv/bin/ruff format --check .
exec .venv/bin/python -m pytest "$@"
