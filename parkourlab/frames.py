"""Results as pandas DataFrames, for scripts that have pandas (the client does not need it).

pandas is imported only when a frame is asked for; without it, :func:`require_pandas` raises an
ImportError that says so and how to get it."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd

NO_PANDAS = "DataFrames need pandas, which is not installed: `pip install pandas` (the client works without it; plain data: Client.runs, Client.results)"  # noqa: E501


def require_pandas():
    """The pandas module, or an ImportError naming pandas and how to install it."""
    try:
        import pandas
    except ImportError as error:
        raise ImportError(NO_PANDAS, name="pandas") from error
    return pandas


def runs_frame(records: list[dict[str, Any]]) -> pd.DataFrame:
    """Runs as the service exports them (one flat record each: ``model.alpha``, ``leg0.zeta0``,
    ``start_xdot`` …, docs/service.md) as a frame indexed by run id, ``created_at`` as UTC
    timestamps."""
    pandas = require_pandas()
    frame = pandas.DataFrame.from_records(records)
    if frame.empty:
        return frame
    frame["created_at"] = pandas.to_datetime(frame["created_at"], utc=True, format="ISO8601")
    return frame.set_index("id")


def results_frame(results: Mapping[str, Any]) -> pd.DataFrame:
    """A job's results as a table: MJTF, one row per energy level (``zeta0`` [l0], ``trials``,
    ``mean``, ``std`` jumps to failure, and an ``outcome.<code>`` count per way a trial ended);
    a sweep, one row per zeta0 point; a gait search, one row per gait; a control study, one row
    per controller (``failure_codes.<code>`` flattened). A basin is a grid, not a table: ValueError
    (its ``result`` is plain data)."""
    pandas = require_pandas()
    kind = results["job"]["kind"]
    if kind == "mjtf":
        return pandas.DataFrame(_levels(results.get("levels") or []))
    result = results.get("result")
    if result is None:
        raise ValueError(f"job {results['job']['id']} has no result yet (state {results['job']['state']})")
    rows = {"sweep": "points", "gaits": "gaits", "control-study": "controllers"}.get(kind)
    if rows is None:
        raise ValueError(f"a {kind} job's result is not a table: use Client.results(job)['result']")
    return pandas.json_normalize(result[rows])


def _levels(levels: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    codes = sorted({code for level in levels for code in level["outcomes"]})
    return [
        {name: level[name] for name in ("zeta0", "trials", "mean", "std")}
        | {f"outcome.{code}": level["outcomes"].get(code, 0) for code in codes}
        for level in levels
    ]
