"""Calibration: the model's parameters fitted to a robot's tracked touchdowns (docs/calibration.md).

What is fitted: ``alpha``, ``c_zeta``, ``c_psi`` (nondimensional, docs/model.md §1) and each leg's
servo offsets of psi0 [deg] and zeta0 [l0] (:class:`~sim_core.model.controls.LegOffsets`); ``d_hat`` and
``mu`` stay the base model's (the chute is measured; friction only shows when a foot slips). The
vector, its names and the report a fit returns are :mod:`sim_core.calibration.fit`'s.

From what: touchdown-to-touchdown pairs. Each measured touchdown is mapped one jump forward by
the model (:mod:`sim_core.calibration.touchdown_model`) and compared with the next measured one on three
channels — ``xdot``, ``ydot`` and the rise between the feet.

From what not: a run that fell (:attr:`TouchdownSeries.fell`) is cut before its fall: the pair into
the touchdown its failing jump began at (:data:`~sim_core.calibration.touchdown_series.FALL_PAIRS`) carries no
steady-state information — a jump on the edge of failing, often a long slow flight no
linearisation holds — and on a real robot the detector may find crossings while it falls. What is
cut is reported: :attr:`~sim_core.calibration.fit.CalibrationFit.cut_at_fall`.

How: least squares (``scipy.optimize.least_squares``, trust region), first with each channel at a
nominal scale, then (:data:`GLS_PASSES` times) with each pair weighted by its own covariance: the
noise of its inputs carried through the map's sensitivities plus the tracker's on its outputs,
at the noise levels most likely at the estimate so far (:mod:`sim_core.calibration.noise`). A jump
near failing, where the map is steep, so counts for little and does not bias the fit; a plain
fit of these runs put its parameters 2-3 times further from the truth than its errors said.

Robust: the whitened residuals (unit variance where the noise is right) go through Huber's loss
beyond :data:`ROBUST_SCALE` sigmas, so a pair the model cannot explain pulls no harder than a
3-sigma one. The noise is estimated from the pairs it explains only (:func:`_inlier_noise`): a
median-absolute-deviation screen first, then pairs whose Mahalanobis distance under the noise
found is below :data:`OUTLIER_SIGMAS`, until the set settles — so one wild pair cannot inflate one
sigma and let the others collapse. The pairs beyond it at the optimum are reported by run and
touchdown: :attr:`~sim_core.calibration.fit.CalibrationFit.outliers`.

How sure: the covariance is a sandwich estimate at the optimum (:func:`_uncertainty`; neighbouring
pairs share a touchdown), its inner inverse from an SVD; standard errors and the correlation
matrix come from it. On 14 seeded sets of four noisy 100-jump climbs the errors of the seven
parameters had standard deviations of 0.9-1.4 standard errors. A direction of parameter space the
data do not constrain (a singular value below :data:`IDENTIFIABLE_RCOND` of the largest) makes
every parameter along it *unidentifiable*: named, with an infinite standard error — not a
measurement. Pairs correlated beyond :data:`CONFOUNDED` are named as hard to tell apart.
"""

from __future__ import annotations

import math

import numpy as np

from sim_core.calibration.fit import PARAMETERS, CalibrationFit, Outlier, split, vector_of
from sim_core.calibration.noise import TouchdownNoise, estimate_noise, pair_covariances, whitening
from sim_core.calibration.touchdown_model import predict_pairs, sensitivities
from sim_core.calibration.touchdown_series import CHANNEL_UNITS, CHANNELS, Pairs, TouchdownSeries, finite_rms
from sim_core.model.controls import LegOffsets
from sim_core.model.params import ModelParams
from sim_core.model.validation import ParameterError

# Per fitted parameter, in PARAMETERS order and units: a step of comparable effect, the bounds searched.
TYPICAL_SCALE = np.array([10.0, 0.3, 0.3, 0.5, 0.5, 0.005, 0.005])
LOWER = np.array([1.0, 0.0, 0.0, -10.0, -10.0, -0.1, -0.1])
UPPER = np.array([1000.0, 20.0, 20.0, 10.0, 10.0, 0.1, 0.1])
NOMINAL_SCATTER = np.array([0.02, 0.02, 0.005])  # first-pass channel scales: xdot, ydot, rise
GLS_PASSES = 2
ROBUST_SCALE = 3.0  # Huber loss: residuals beyond 3 channel sigmas count linearly, not squared
# A pair whose Mahalanobis distance under the estimated noise is beyond this is an outlier: left out
# of the noise estimate, reported. sqrt of chi-square(3 channels)'s 99.9 % point: 1 honest pair in 1000.
OUTLIER_SIGMAS = 4.03
SCREEN_MADS = 5.0  # first noise estimate: pairs within 5 scaled MADs of the median on every channel
MAD_TO_SIGMA = 1.4826  # a Gaussian's sigma per median absolute deviation
INLIER_PASSES = 4
FAILED_RESIDUAL = 10.0  # a pair whose predicted jump fails, in channel scales (bounded, so the fit moves on)
IDENTIFIABLE_RCOND = 1e-6
CONFOUNDED = 0.95  # |correlation| above which two parameters are reported as hard to tell apart
MIN_PAIRS = 10


def predict(pairs: Pairs, model: ModelParams, offsets: LegOffsets) -> tuple[np.ndarray, int]:
    """Predicted ``(xdot, ydot, rise)`` of each pair's second touchdown (NaN rows: failed), and the failures."""
    out = np.empty((len(pairs), 3))
    psi0 = np.radians(np.asarray(offsets.psi0_offset_deg, dtype=float))
    zeta0 = np.asarray(offsets.zeta0_offset, dtype=float)
    failed = predict_pairs(pairs.before, pairs.after, model.record(), psi0, zeta0, out)
    return out, int(failed)


def calibrate(series: list[TouchdownSeries], base: ModelParams, start: LegOffsets | None = None) -> CalibrationFit:
    """Fit ``alpha``, ``c_zeta``, ``c_psi`` and the leg offsets to ``series``, starting from ``base``.

    Raises :class:`ParameterError` (field ``runs``) with fewer than :data:`MIN_PAIRS` consecutive pairs.
    """
    from scipy.optimize import least_squares

    pairs = Pairs.of(series, steady=True)
    if len(pairs) < MIN_PAIRS:
        raise ParameterError(
            "runs", f"need at least {MIN_PAIRS} consecutive touchdown pairs to calibrate, the runs give {len(pairs)}"
        )
    measured = pairs.measured()
    x0 = np.clip(vector_of(base, start or LegOffsets()), LOWER, UPPER)

    def residuals(vector: np.ndarray, whiten: np.ndarray, kept: np.ndarray) -> np.ndarray:
        predicted, _ = predict(pairs, *split(base, vector))
        whitened = np.einsum("ijk,ik->ij", whiten, predicted - measured)
        return (np.nan_to_num(whitened, nan=FAILED_RESIDUAL) * kept[:, None]).ravel()

    def fitted(x: np.ndarray, whiten: np.ndarray, kept: np.ndarray):
        return least_squares(residuals, x, args=(whiten, kept), bounds=(LOWER, UPPER), x_scale=TYPICAL_SCALE,
                             loss="huber", f_scale=ROBUST_SCALE, diff_step=1e-6, method="trf", xtol=1e-10,
                             ftol=1e-10)  # fmt: skip

    before, _ = predict(pairs, *split(base, x0))
    # First each channel by a nominal scale, then (GLS_PASSES times) each pair by its own covariance
    # under the noise most likely, from the pairs it explains, at the estimate so far.
    inliers = np.ones(len(pairs), dtype=bool)
    fit = fitted(x0, np.broadcast_to(np.diag(1.0 / NOMINAL_SCATTER), (len(pairs), 3, 3)), inliers)
    noise = TouchdownNoise()
    for _ in range(GLS_PASSES):
        model, offsets = split(base, fit.x)
        predicted, _ = predict(pairs, model, offsets)
        sensitivity = _sensitivities(pairs, model, offsets)
        noise, inliers = _inlier_noise(predicted - measured, sensitivity, noise)
        fit = fitted(fit.x, _whitening(sensitivity, noise), inliers)
    model, offsets = split(base, fit.x)
    after, failed = predict(pairs, model, offsets)
    distance = _distances(after - measured, _sensitivities(pairs, model, offsets), noise)
    rows = np.repeat(inliers, len(CHANNELS))  # the pairs the last pass fitted
    stderr, correlation, unidentifiable = _uncertainty(fit.jac[rows], fit.fun[rows])  # of the weighted residuals
    channels = {
        name: {"unit": CHANNEL_UNITS[name], "rms_before": finite_rms(before[:, i] - measured[:, i]),
               "rms_after": finite_rms(after[:, i] - measured[:, i])}
        for i, name in enumerate(CHANNELS)
    }  # fmt: skip
    outlying = np.flatnonzero(~(distance < OUTLIER_SIGMAS))
    return CalibrationFit(
        model=model,
        offsets=offsets,
        stderr=dict(zip(PARAMETERS, stderr.tolist(), strict=True)),
        correlation=correlation,
        unidentifiable=unidentifiable,
        confounded=_confounded(correlation),
        touchdowns_used=len(pairs),
        rms_before=finite_rms(before[:, :2] - measured[:, :2]),
        rms_after=finite_rms(after[:, :2] - measured[:, :2]),
        channels=channels,
        noise=noise.to_dict(),
        failed_predictions=failed,
        outliers=tuple(Outlier(int(pairs.origin[i, 0]), int(pairs.origin[i, 1]), float(distance[i])) for i in outlying),
        cut_at_fall=_cut_at_fall(series),
        noise_pairs=int(np.count_nonzero(inliers)),
    )


def _cut_at_fall(series: list[TouchdownSeries]) -> tuple[tuple[int, int], ...]:
    """``(position, first touchdown not predicted)`` of each run that fell and lost pairs to it."""
    cut = []
    for position, run in enumerate(series):
        dropped = np.flatnonzero(run.consecutive & ~run.steady)
        if dropped.size:
            cut.append((position, int(dropped[0]) + 1))
    return tuple(cut)


def _inlier_noise(residuals: np.ndarray, sensitivity: np.ndarray, start: TouchdownNoise):
    """The noise most likely from the pairs it explains, and which those are (shape (pairs,)).

    A median-absolute-deviation screen of the residuals picks the first pairs; then, until the set
    settles (at most :data:`INLIER_PASSES` times), the noise is estimated from the set and the set
    becomes the pairs within :data:`OUTLIER_SIGMAS` of it. A pair near failing, with a large
    residual its own covariance explains, comes back in; a pair nothing explains stays out.
    """
    usable = np.isfinite(residuals).all(axis=1) & np.isfinite(sensitivity).all(axis=(1, 2))
    centre = np.median(residuals[usable], axis=0)
    spread = MAD_TO_SIGMA * np.median(np.abs(residuals[usable] - centre), axis=0)
    with np.errstate(invalid="ignore"):
        inliers = usable & np.all(np.abs(residuals - centre) <= SCREEN_MADS * spread, axis=1)
    noise = start
    for _ in range(INLIER_PASSES):
        noise = estimate_noise(residuals[inliers], sensitivity[inliers], noise)
        settled = _distances(residuals, sensitivity, noise) < OUTLIER_SIGMAS
        if np.array_equal(settled, inliers):
            break
        inliers = settled
    return noise, inliers


def _distances(residuals: np.ndarray, sensitivity: np.ndarray, noise: TouchdownNoise) -> np.ndarray:
    """Shape (pairs,): each pair's Mahalanobis distance [sigmas] under ``noise``; inf where its jump fails."""
    usable = np.isfinite(residuals).all(axis=1) & np.isfinite(sensitivity).all(axis=(1, 2))
    distance = np.full(residuals.shape[0], math.inf)
    r = residuals[usable]
    solved = np.linalg.solve(pair_covariances(sensitivity[usable], noise), r[:, :, None])[:, :, 0]
    distance[usable] = np.sqrt(np.einsum("ij,ij->i", r, solved))
    return distance


def _confounded(correlation: np.ndarray) -> tuple[tuple[str, str, float], ...]:
    pairs = []
    for i in range(len(PARAMETERS)):
        for j in range(i + 1, len(PARAMETERS)):
            value = correlation[i, j]
            if math.isfinite(value) and abs(value) > CONFOUNDED:
                pairs.append((PARAMETERS[i], PARAMETERS[j], round(float(value), 4)))
    return tuple(pairs)


def _sensitivities(pairs: Pairs, model: ModelParams, offsets: LegOffsets) -> np.ndarray:
    psi0 = np.radians(np.asarray(offsets.psi0_offset_deg, dtype=float))
    return sensitivities(pairs, model.record(), psi0, np.asarray(offsets.zeta0_offset, dtype=float))


def _whitening(sensitivity: np.ndarray, noise: TouchdownNoise) -> np.ndarray:
    """Each pair's whitening under ``noise``; a pair whose jump fails gets the nominal channel scales."""
    usable = np.isfinite(sensitivity).all(axis=(1, 2))
    whiten = np.broadcast_to(np.diag(1.0 / NOMINAL_SCATTER), (sensitivity.shape[0], 3, 3)).copy()
    whiten[usable] = whitening(pair_covariances(sensitivity[usable], noise))
    return whiten


def _uncertainty(jacobian: np.ndarray, residuals: np.ndarray) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Standard errors, correlation and the unidentifiable parameters at the optimum.

    ``jacobian`` is least_squares' (rows scaled by the Huber loss's weights), ``residuals`` the
    weighted residuals, three per pair in pair order. The covariance is the sandwich
    ``A^-1 B A^-1`` (``A = J^T J``): ``B`` sums the pairs' scores with Newey–West weights over two
    neighbours, because neighbouring pairs share a touchdown and their errors are not independent,
    and the errors grow where the map is sensitive. ``s^2 (J^T J)^-1`` would claim more certainty.
    """
    m, p = jacobian.shape
    weights = np.minimum(1.0, ROBUST_SCALE / np.maximum(np.abs(residuals), 1e-300))
    scaled = np.sqrt(weights) * residuals  # as least_squares scaled the Jacobian's rows
    _, singular, vt = np.linalg.svd(jacobian, full_matrices=False)
    strong = singular > IDENTIFIABLE_RCOND * singular[0]
    # Parameters with weight in a direction the data do not constrain cannot be told apart.
    weak = np.any(np.abs(vt[~strong]) > 0.1, axis=0) if not strong.all() else np.zeros(p, dtype=bool)
    inverse = (vt[strong].T / singular[strong] ** 2) @ vt[strong]
    scores = (jacobian * scaled[:, None]).reshape(-1, len(CHANNELS), p).sum(axis=1)
    middle = scores.T @ scores
    for lag, weight in ((1, 2 / 3), (2, 1 / 3)):
        cross = scores[lag:].T @ scores[:-lag]
        middle += weight * (cross + cross.T)
    covariance = inverse @ middle @ inverse * (m / max(m - p, 1))
    stderr = np.sqrt(np.clip(np.diag(covariance), 0.0, None))
    stderr[weak] = math.inf
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = covariance / np.outer(stderr, stderr)
    correlation[weak, :] = np.nan
    correlation[:, weak] = np.nan
    return stderr, correlation, tuple(name for name, flag in zip(PARAMETERS, weak, strict=True) if flag)


def one_jump_predictions(series: TouchdownSeries, models: dict[str, tuple[ModelParams, LegOffsets]]) -> dict:
    """Each touchdown of ``series`` that follows a measured one, predicted from it by each model.

    Returns ``{"index": [k...], "measured": (n, 3), name: (n, 3) ...}`` — columns ``xdot, ydot, rise``
    of touchdown ``k`` (the rise from touchdown ``k - 1``), NaN where a model's jump fails.
    """
    pairs = Pairs.of([series])
    result = {"index": (np.flatnonzero(series.consecutive) + 1).tolist(), "measured": pairs.measured()}
    for name, (model, offsets) in models.items():
        result[name] = predict(pairs, model, offsets)[0]
    return result
