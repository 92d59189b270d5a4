#!/usr/bin/env bash
# The main job: set up .venv/ if needed, then start the ParkourLab service (`parkour serve`:
# REST API and experiment store on SQLite in ./data, bound to 127.0.0.1:8000).
# Arguments go to `parkour` instead, e.g. ./run.sh map --state -0.93 -0.17 --jumps 5
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
"$root/scripts/ensure-venv.sh"
if [ $# -eq 0 ]; then
  set -- serve --data-dir "$root/data"
fi
exec "$root/.venv/bin/parkour" "$@"
