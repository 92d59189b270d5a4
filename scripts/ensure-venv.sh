#!/usr/bin/env bash
# Create .venv/ at the repository root and install ParkourLab into it (editable, pinned
# dependencies from pyproject.toml). Re-installs only when pyproject.toml changes.
# Usage: scripts/ensure-venv.sh [dev]   ("dev" adds the test and lint tools)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
extras="${1:-}"

find_python() {
  for candidate in "${PYTHON:-}" python3.11 python3.12 python3.13 python3; do
    [ -n "$candidate" ] || continue
    if command -v "$candidate" >/dev/null 2>&1 &&
      "$candidate" -c 'import sys; sys.exit(not ((3, 11) <= sys.version_info[:2] < (3, 14)))' 2>/dev/null; then
      echo "$candidate"
      return
    fi
  done
  echo "error: ParkourLab needs Python 3.11-3.13 (set PYTHON=/path/to/python3.11)" >&2
  exit 2
}

if [ ! -x "$root/.venv/bin/python" ]; then
  python="$(find_python)"
  echo "creating .venv/ with $("$python" --version)" >&2
  "$python" -m venv "$root/.venv"
fi
stamp="$root/.venv/.parkour-installed${extras:+-$extras}"
wanted="$(sha256sum "$root/pyproject.toml" | cut -c1-16)"
if [ "$(cat "$stamp" 2>/dev/null || true)" != "$wanted" ]; then
  echo "installing ParkourLab${extras:+ [$extras]} into .venv/ (first run takes a minute)" >&2
  "$root/.venv/bin/python" -m pip install --quiet --disable-pip-version-check -e "$root${extras:+[$extras]}"
  echo "$wanted" >"$stamp"
fi
