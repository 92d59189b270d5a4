#!/usr/bin/env bash
# The test suite: set up .venv/ with the dev tools if needed, lint, then run every test.
# With no arguments it runs the whole suite (two workers, then the real-time tests alone);
# arguments go to pytest as they are,
# e.g. ./test.sh -m "not slow" or ./test.sh tests/sim_core
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
# With no arguments, the whole suite, in two parts. First everything but the real-time tests, on
# $PARKOUR_TEST_WORKERS processes (default 2; 0 runs them in this one), a test file to a worker at a
# time so that a file's tests keep their order and fixtures: most of the suite waits on browsers,
# sockets and a robot in real time, so two workers take about half the time even on two cores.
# Then the tests marked realtime (an e-stop acknowledged within 150 ms, a closed loop answering
# within a stance), alone on the machine, as the robot's PC would be. With arguments, pytest gets
# exactly those.
if [ $# -gt 0 ]; then
  exec .venv/bin/python -m pytest "$@"
fi
status=0
.venv/bin/python -m pytest -n "${PARKOUR_TEST_WORKERS:-2}" --dist loadfile -m "not realtime" || status=$?
.venv/bin/python -m pytest -m realtime || status=$((status ? status : $?))
exit "$status"
