"""The paper's stable *descending* period-1 gaits (Fig. 8's text), tested over the leg angle.

For each psi0 of a scan, the symmetric period-1 gait is followed over zeta0 by continuation
(:func:`sim_core.basins.sweep.energy_sweep`) on a coarse sweep that locates its zeta0 of jumping in
place, then on a fine sweep from there up to ``span`` past it, where the gait descends (climb per
jump < 0). The psi0 holds stable descending gaits when a point of the fine sweep past jumping in
place descends with max |λ| < 1; the row keeps max |λ| just past jumping in place and the
fastest stable descent.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from experiments.report import Claim
from sim_core.basins.sweep import energy_sweep, zeta0_values
from sim_core.model.params import ModelParams

COARSE_ZETA0 = (0.80, 0.99)  # where the coarse sweep looks for the zeta0 of jumping in place
ZETA0_CEILING = 0.999  # the fine sweep stops short of a leg at full length


@dataclass(frozen=True)
class DescendingRow:
    """One psi0 of the scan. The descending fields are None where no gait descends stably.

    Attributes:
        psi0_deg: the leg angle of both legs [deg].
        in_place_zeta0: where the gait jumps in place (None: its climb keeps its sign).
        first_eigenvalue: max |λ| of the first descending gait of the fine sweep (just past in place).
        stable_up_to: the largest zeta0 of the fine sweep whose gait descends with max |λ| < 1.
        steepest_climb: the climb per jump there [l0/jump], the fastest stable descent found.
    """

    psi0_deg: float
    in_place_zeta0: float | None
    first_eigenvalue: float | None
    stable_up_to: float | None
    steepest_climb: float | None

    @property
    def stable(self) -> bool:
        return self.stable_up_to is not None


def descending_gaits(
    model: ModelParams,
    psi0s_deg: Sequence[float],
    *,
    span: float = 0.03,
    steps: int = 41,
    coarse_steps: int = 20,
    guess=None,
) -> tuple[DescendingRow, ...]:
    """The stable descending period-1 gaits at each psi0 [deg], if any.

    Args:
        span: how far past the zeta0 of jumping in place the fine sweep goes [l0 of zeta0].
        steps, coarse_steps: zeta0 values of the fine sweep (from the coarse sweep's last gait
            below jumping in place) and of the coarse sweep (over ``COARSE_ZETA0``).
        guess: a section state near the gait at the first psi0's first zeta0; each later psi0
            starts from the previous one's first gait.
    """
    rows = []
    seed = guess
    for psi0_deg in psi0s_deg:
        psi0 = math.radians(psi0_deg)
        coarse = energy_sweep(model, psi0, zeta0_values(*COARSE_ZETA0, coarse_steps), guess=seed)
        found = [p for p in coarse.points if p.gait is not None]
        seed = found[0].gait.state if found else None
        below = [p for p in found if coarse.in_place_zeta0 and p.zeta0 < max(coarse.in_place_zeta0)]
        if not below:
            rows.append(DescendingRow(float(psi0_deg), None, None, None, None))
            continue
        in_place = max(coarse.in_place_zeta0)
        fine = energy_sweep(
            model,
            psi0,
            zeta0_values(below[-1].zeta0, min(in_place + span, ZETA0_CEILING), steps),
            guess=below[-1].gait.state,
        )
        descending = [p for p in fine.points if p.gait is not None and p.zeta0 > in_place and p.climb_per_jump < 0.0]
        stable = [p for p in descending if p.gait.max_abs_eigenvalue < 1.0]
        first = descending[0].gait.max_abs_eigenvalue if descending else None
        last = stable[-1] if stable else None
        rows.append(
            DescendingRow(
                float(psi0_deg),
                in_place,
                first,
                None if last is None else last.zeta0,
                None if last is None else last.climb_per_jump,
            )
        )
    return tuple(rows)


def stable_psi0_range(rows: Sequence[DescendingRow]) -> tuple[float, float] | None:
    """The smallest and largest psi0 [deg] with a stable descending gait, or None."""
    stable = [row.psi0_deg for row in rows if row.stable]
    return (min(stable), max(stable)) if stable else None


def descending_claim(rows: Sequence[DescendingRow]) -> Claim:
    """The paper's stable descending period-1 gaits, against the scan."""
    paper = "Stable descending period-1 gaits (climb per jump < 0, max |λ| < 1)"
    scanned = f"{len(rows)} angles scanned over psi0 {_degrees(rows[0].psi0_deg, rows[-1].psi0_deg)}"
    held = stable_psi0_range(rows)
    if held is None:
        return Claim(paper, f"none at the {scanned}: every descending gait found has max |λ| ≥ 1", False)
    stable = [row for row in rows if row.stable]
    lam = [row.first_eigenvalue for row in stable]
    gaps = [f"{row.psi0_deg:g}°" for row in rows if held[0] < row.psi0_deg < held[1] and not row.stable]
    steepest = min(stable, key=lambda row: row.steepest_climb)
    return Claim(
        paper,
        f"{'only ' if len(stable) < len(rows) else ''}at psi0 {_degrees(*held)} ({scanned})"
        + (f" (not at {', '.join(gaps)})" if gaps else "")
        + f", just past jumping in place: max |λ| {min(lam):.3f}–{max(lam):.3f} there, rising to 1 within "
        f"{max(row.stable_up_to - row.in_place_zeta0 for row in stable):.3f} of zeta0; the fastest stable descent "
        f"{steepest.steepest_climb:+.4f} l0/jump (psi0 {steepest.psi0_deg:g}°, zeta0 {steepest.stable_up_to:.4f})",
        True,
    )


def _degrees(low: float, high: float) -> str:
    return f"{low:g}°" if low == high else f"{low:g}–{high:g}°"


def table_columns(rows: Sequence[DescendingRow]) -> dict[str, np.ndarray]:
    """The scan as CSV columns (NaN where no descending gait)."""

    def column(name: str) -> np.ndarray:
        return np.array([math.nan if getattr(row, name) is None else getattr(row, name) for row in rows])

    return {
        "descending_psi0_deg": column("psi0_deg"),
        "descending_in_place_zeta0": column("in_place_zeta0"),
        "descending_first_max_abs_eigenvalue": column("first_eigenvalue"),
        "descending_stable_up_to_zeta0": column("stable_up_to"),
        "descending_steepest_climb_l0": column("steepest_climb"),
    }
