#!/usr/bin/env bash
# The main job: set up .venv/ if needed, then start the ParkourLab service (`parkour serve`:
# REST API and experiment store on SQLite in ./data, or the database DATABASE_URL names; bound to
# 127.0.0.1:8000).
# Arguments go to `parkour` instead, e.g. ./run.sh map --state -0.93 -0.17 --jumps 5
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
# PostgreSQL (DATABASE_URL=postgresql://user@host/db) needs its driver, the "postgres" extra.
case "${DATABASE_URL:-}" in
  postgresql*) "$root/scripts/ensure-venv.sh" postgres ;;
  *) "$root/scripts/ensure-venv.sh" ;;
esac
if [ $# -eq 0 ]; then
  set -- serve --data-dir "$root/data"
fi
exec "$root/.venv/bin/parkour" "$@"
