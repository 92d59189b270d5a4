#!/usr/bin/env bash
# The main job: set up .venv/ if needed, then run `parkour` (default: the paper's gaits).
# Any arguments go to `parkour`, e.g. ./run.sh map --state -0.93 -0.17 --jumps 5
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
"$root/scripts/ensure-venv.sh"
if [ $# -eq 0 ]; then
  set -- gaits --controls 30:0.9
  echo "parkour $* (run ./run.sh --help for every command)" >&2
fi
exec "$root/.venv/bin/parkour" "$@"
