"""What a calibration fits and what it reports (docs/calibration.md, "What is fitted", "How sure").

The fitted vector is seven numbers in :data:`PARAMETERS` order: ``alpha``, ``c_zeta``, ``c_psi``
(nondimensional, docs/model.md §1), then each leg's servo offsets of psi0 [deg] and zeta0 [l0]
(:class:`~sim_core.model.controls.LegOffsets`). :func:`vector_of` packs a model and offsets into it and
:func:`split` unpacks it onto a base model, whose other parameters it keeps.

:class:`CalibrationFit` is the result of :func:`sim_core.calibration.calibrate.calibrate`: the fitted model
and offsets with their standard errors, correlations and what the data cannot tell apart, the
residuals before and after, the noise estimated, the pairs the fit does not explain
(:class:`Outlier`) and those cut at a fall. Its :meth:`CalibrationFit.to_dict` is the
``parkour calibrate --json`` contract.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from sim_core.model.controls import LegOffsets
from sim_core.model.params import ModelParams

# The fitted vector, in order: its names in the JSON, and the units the fit works in.
PARAMETERS = ("alpha", "c_zeta", "c_psi", "psi0_offset_deg.left", "psi0_offset_deg.right",
              "zeta0_offset.left", "zeta0_offset.right")  # fmt: skip


def vector_of(model: ModelParams, offsets: LegOffsets) -> np.ndarray:
    """Shape (7,): ``model``'s fitted parameters and ``offsets`` in :data:`PARAMETERS` order and units."""
    return np.array([model.alpha, model.c_zeta, model.c_psi, *offsets.psi0_offset_deg, *offsets.zeta0_offset])


def split(base: ModelParams, vector: np.ndarray) -> tuple[ModelParams, LegOffsets]:
    """``vector`` (7,), in :data:`PARAMETERS` order, as ``base`` with its fitted parameters and the leg offsets."""
    model = replace(base, alpha=float(vector[0]), c_zeta=float(vector[1]), c_psi=float(vector[2]))
    offsets = LegOffsets(psi0_offset_deg=(float(vector[3]), float(vector[4])),
                         zeta0_offset=(float(vector[5]), float(vector[6])))  # fmt: skip
    return model, offsets


@dataclass(frozen=True)
class Outlier:
    """A touchdown pair the fit does not explain.

    Attributes:
        series: the run's position in the series given to :func:`sim_core.calibration.calibrate.calibrate`.
        touchdown: index ``k + 1`` in that run of the touchdown predicted from touchdown ``k``.
        residual: the pair's Mahalanobis distance [sigmas] under its covariance at the fit (3
            channels); inf where the fitted model's jump fails.
    """

    series: int
    touchdown: int
    residual: float

    def to_dict(self) -> dict:
        return {"series": self.series, "touchdown": self.touchdown, "residual": self.residual}


@dataclass(frozen=True)
class CalibrationFit:
    """A fitted model with its uncertainty.

    Attributes:
        model: the base model with the fitted ``alpha``, ``c_zeta``, ``c_psi``.
        offsets: the fitted leg offsets.
        stderr: standard error per name of :data:`PARAMETERS` (inf: not identifiable).
        correlation: (7, 7) correlation matrix in :data:`PARAMETERS` order (NaN rows: unidentifiable).
        unidentifiable: names the data do not constrain at all (a singular direction).
        confounded: pairs ``(a, b, correlation)`` with ``|correlation| >``
            :data:`~sim_core.calibration.calibrate.CONFOUNDED`: the data pin down a combination of the two
            better than either (e.g. the legs' zeta0 offsets, whose sum sets the energy) — read
            their values with their standard errors.
        touchdowns_used: pairs compared (each a touchdown the model predicted).
        rms_before, rms_after: RMS one-jump error of the section state [sqrt(g l0)], base vs fitted.
        channels: per channel ``{"unit", "rms_before", "rms_after"}``.
        noise: the noise levels most likely at the fit (:class:`sim_core.calibration.noise.TouchdownNoise`).
        failed_predictions: pairs whose predicted jump failed with the fitted model.
        outliers: the pairs the fitted model and noise do not explain (:class:`Outlier`), in run order.
        cut_at_fall: ``(series, touchdown)`` per run that fell: the position of the run in the
            series given and the first of its touchdowns not predicted (docs/calibration.md, "Falls").
        noise_pairs: the pairs the noise was estimated from (the compared ones less the outliers).
    """

    model: ModelParams
    offsets: LegOffsets
    stderr: dict[str, float]
    correlation: np.ndarray
    unidentifiable: tuple[str, ...]
    confounded: tuple[tuple[str, str, float], ...]
    touchdowns_used: int
    rms_before: float
    rms_after: float
    channels: dict[str, dict]
    noise: dict[str, float]
    failed_predictions: int
    outliers: tuple[Outlier, ...] = ()
    cut_at_fall: tuple[tuple[int, int], ...] = ()
    noise_pairs: int = 0

    def to_dict(self) -> dict:
        """The ``parkour calibrate --json`` contract (NaN and inf become null in JSON)."""
        se = self.stderr
        return {
            "params": {
                "alpha": self.model.alpha,
                "c_zeta": self.model.c_zeta,
                "c_psi": self.model.c_psi,
                **self.offsets.to_dict(),
            },
            "stderr": {
                "alpha": se["alpha"],
                "c_zeta": se["c_zeta"],
                "c_psi": se["c_psi"],
                "psi0_offset_deg": [se["psi0_offset_deg.left"], se["psi0_offset_deg.right"]],
                "zeta0_offset": [se["zeta0_offset.left"], se["zeta0_offset.right"]],
            },
            "parameters": list(PARAMETERS),
            "correlation": self.correlation.tolist(),
            "unidentifiable": list(self.unidentifiable),
            "confounded": [list(pair) for pair in self.confounded],
            "touchdowns_used": self.touchdowns_used,
            "rms_residual_before": self.rms_before,
            "rms_residual_after": self.rms_after,
            "residuals": self.channels,
            "noise": self.noise,
            "failed_predictions": self.failed_predictions,
            "outliers": [outlier.to_dict() for outlier in self.outliers],
            "cut_at_fall": [{"series": series, "touchdown": touchdown} for series, touchdown in self.cut_at_fall],
            "noise_pairs": self.noise_pairs,
        }
