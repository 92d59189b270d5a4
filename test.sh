#!/usr/bin/env bash
# The test suite: set up .venv/ with the dev tools if needed, lint, then run every test.
# Arguments go to pytest, e.g. ./test.sh -m "not slow" or ./test.sh tests/sim_core
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$root"
scripts/ensure-venv.sh dev
# The browser tests drive Debian's Chromium through Playwright; install it when we can (root with
# apt), otherwise those tests skip and say why.
if ! command -v chromium >/dev/null 2>&1 && [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  echo "installing Chromium for the browser tests (Debian package)" >&2
  { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium; } >/dev/null 2>&1 ||
    echo "could not install Chromium: the browser tests will be skipped" >&2
fi
.venv/bin/ruff check .
.venv/bin/ruff format --check .
exec .venv/bin/python -m pytest "$@"
