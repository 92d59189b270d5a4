"""How long ``parkour`` makes a person wait before it does anything: start-up, side by side with
``python -c "import numpy"`` timed in the same run.

Figures (median of ``--repeats`` runs each, with warm caches: numba's, the OS's, and Python's
bytecode, which this script compiles once when the environment sets PYTHONDONTWRITEBYTECODE):

- ``help``: ``parkour --help``;
- ``map_help``: ``parkour map --help``, and which heavy packages it imported (it should import
  none of scipy.optimize, SQLAlchemy, Alembic, Dask, matplotlib, viser);
- ``map``: ``parkour map --jumps 10 --state -0.93 -0.17 --json``;
- ``numba_floor``: a fresh interpreter calling a trivial cached ``@njit`` function — what numba's own
  import and first dispatch cost before any of ParkourLab's work (the floor under ``map``);
- ``serve``: ``parkour serve`` from launch to the first 200 from ``/api/v1/health`` (3D view on),
  on a data directory that exists, as on every start but the first;
- ``serve_first``: the same on a new data directory each time (the schema is created first).

Each is also reported as a ratio to the numpy import, which makes runs on a busy or a different
machine comparable. ``--command`` times another checkout's entry point, e.g. an older commit:
``--command "python -m frontend.cli" --module frontend.cli`` with ``PYTHONPATH`` set to that tree.

    python scripts/bench_startup.py [--repeats 5] [--json]     (from the checkout's root)
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

HEAVY = ("scipy.optimize", "sqlalchemy", "alembic", "dask", "distributed", "matplotlib", "viser", "fastapi")
SERVE_TIMEOUT_S = 60.0
MAP_ARGS = ("map", "--jumps", "10", "--state", "-0.93", "-0.17", "--json")
TRIVIAL_KERNEL = "import numba\n\n\n@numba.njit(cache=True)\ndef one_more(x):\n    return x + 1.0\n"
# The interpreter's view of what a command imported, printed at exit: run the entry point inside it.
_PROBE = (
    "import atexit, sys, json, runpy; "
    "atexit.register(lambda: sys.stderr.write('\\nIMPORTED ' + json.dumps(sorted(sys.modules)) + '\\n')); "
    "module = sys.argv[1]; sys.argv = ['parkour', *sys.argv[2:]]; runpy.run_module(module, run_name='__main__')"
)


def default_command() -> list[str]:
    """This checkout's ``parkour`` script, next to the running interpreter."""
    script = Path(sys.executable).with_name("parkour")
    return [str(script)] if script.exists() else [sys.executable, "-m", "cli"]


def timed(argv: list[str]) -> float:
    """Wall-clock seconds of one run of ``argv``, which must succeed."""
    start = time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def serve_until_healthy(command: list[str], data_dir: str | None = None) -> float:
    """Seconds from launching ``parkour serve`` to a 200 from /api/v1/health (a new data directory
    unless ``data_dir``)."""
    if data_dir is None:
        with tempfile.TemporaryDirectory() as new:
            return serve_until_healthy(command, new)
    port, view_port = free_port(), free_port()
    argv = [*command, "serve", "--data-dir", data_dir, "--port", str(port), "--view-port", str(view_port)]
    start = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while time.perf_counter() - start < SERVE_TIMEOUT_S:
            if process.poll() is not None:
                raise RuntimeError(f"parkour serve exited with {process.returncode}")
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/api/v1/health", timeout=1) as reply:
                    if reply.status == 200:
                        return time.perf_counter() - start
            except OSError:
                time.sleep(0.01)
        raise RuntimeError(f"parkour serve was not healthy within {SERVE_TIMEOUT_S} s")
    finally:
        process.terminate()
        process.wait(10)


def imported_by(module: str, argv: list[str]) -> list[str]:
    """The heavy packages ``parkour ARGS`` imports, run as ``python -m MODULE`` in this interpreter."""
    result = subprocess.run(
        [sys.executable, "-c", _PROBE, module, *argv], capture_output=True, text=True, check=True, env=os.environ.copy()
    )
    line = next(line for line in result.stderr.splitlines() if line.startswith("IMPORTED "))
    modules = set(json.loads(line.removeprefix("IMPORTED ")))
    return [name for name in HEAVY if name in modules]


def numba_floor_command(directory: str) -> list[str]:
    """A command that calls a trivial cached numba kernel, written into ``directory``."""
    Path(directory, "trivial_kernel.py").write_text(TRIVIAL_KERNEL)
    probe = f"import sys; sys.path.insert(0, {directory!r}); import trivial_kernel; trivial_kernel.one_more(1.0)"
    return [sys.executable, "-c", probe]


def warm_caches(command: list[str], data_dir: str) -> None:
    """Compile the project's bytecode (as any Python that may write it does on first import), fill
    numba's cache and the OS file cache, and create the schema in ``data_dir``."""
    packages = [name for name in ("cli", "sim_core", "experiments", "backend", "frontend") if Path(name).is_dir()]
    subprocess.run([sys.executable, "-m", "compileall", "-q", *packages], check=True, stdout=subprocess.DEVNULL)
    timed([*command, *MAP_ARGS])
    serve_until_healthy(command, data_dir)


def run(command: list[str], module: str, repeats: int) -> dict:
    numpy_import = [sys.executable, "-c", "import numpy"]
    names = ("numpy_import", "help", "map_help", "numba_floor", "map", "serve", "serve_first")
    samples: dict[str, list[float]] = {name: [] for name in names}
    with tempfile.TemporaryDirectory() as data_dir, tempfile.TemporaryDirectory() as kernel_dir:
        numba_floor = numba_floor_command(kernel_dir)
        timed(numba_floor)  # compiles and caches it
        warm_caches(command, data_dir)
        for _ in range(repeats):  # interleaved, so a burst of load hits every figure alike
            samples["numpy_import"].append(timed(numpy_import))
            samples["numba_floor"].append(timed(numba_floor))
            samples["help"].append(timed([*command, "--help"]))
            samples["map_help"].append(timed([*command, "map", "--help"]))
            samples["map"].append(timed([*command, *MAP_ARGS]))
            samples["serve"].append(serve_until_healthy(command, data_dir))
            samples["serve_first"].append(serve_until_healthy(command))
    medians = {name: statistics.median(values) for name, values in samples.items()}
    return {
        "command": shlex.join(command),
        "repeats": repeats,
        "seconds": medians,
        "ratio_to_numpy_import": {
            name: value / medians["numpy_import"] for name, value in medians.items() if name != "numpy_import"
        },
        "map_help_imports": imported_by(module, ["map", "--help"]),
        "help_imports": imported_by(module, ["--help"]),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="runs of each figure; the median is reported")
    parser.add_argument("--command", help="the parkour entry point to time (default: this checkout's)")
    parser.add_argument("--module", default="cli", help="the entry point's module, for the import check")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args()
    command = shlex.split(args.command) if args.command else default_command()
    result = run(command, args.module, args.repeats)
    if args.json:
        print(json.dumps(result, indent=2))
        return
    print(f"{result['command']}: median of {args.repeats}")
    for name, seconds in result["seconds"].items():
        ratio = result["ratio_to_numpy_import"].get(name)
        print(f"  {name:<13} {seconds:6.3f} s" + ("" if ratio is None else f"   {ratio:5.1f}x numpy import"))
    print(f"  parkour --help imports:     {', '.join(result['help_imports']) or 'none of ' + ', '.join(HEAVY)}")
    print(f"  parkour map --help imports: {', '.join(result['map_help_imports']) or 'none of ' + ', '.join(HEAVY)}")


if __name__ == "__main__":
    main()
