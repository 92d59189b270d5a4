"""The grid the MFPT chain lives on (:mod:`sim_core.robustness.mfpt`): its options, the noise quadrature, the
pitch stencil and the axes and states fitted to where noisy paths go.

The state is the mid-chute section's ``(xdot, ydot, pitch)`` (:mod:`sim_core.model.noisy_map`). The
pitch lives on nodes ``(i - c) h`` symmetric about 0, so a pitch's negative is a node and the
random walk's step is a discrete Gaussian over whole nodes (never interpolated). The velocity
lives on a rectilinear grid: uniform spacing over the *core* where noisy paths spend their time,
spacing growing geometrically outside it out to the window, so a node where the chain matters is
close to its neighbours (bilinear sharing adds a variance of up to ``h² / 4`` a jump, which must
stay small beside the noise's own) while the window still reaches where the gait's basin ends.
Only the states near where paths go are kept when the pitch drifts (a random walk, so each
pitch layer sees a narrow band of velocities); without drift, every node of the window is.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from sim_core.model.validation import ParameterError, check_range

MAX_STATES = 2_000_000  # about 2 GB of transition rows at the finest rule: refused before allocating
MAX_PATH_JUMPS = 10_000_000  # the exploring paths' jumps: their draws are held at once (400 MB)
MAX_PAIRS = 3_000_000  # pairs whose jumps are run (each a few hundred stances): an hour at the finest rule
TAIL_GROWTH = 1.25  # spacing ratio of consecutive nodes outside the core
CORE_PERCENTILES = (5.0, 95.0)  # the core: where paths spend 90% of their time (each axis)
DEFAULT_HALF_WIDTH = 3.0  # [sqrt(g l0)] the window around the paths' median state
TAIL_WIDENING = 2.0  # the strata are equiprobable for a Gaussian this many times wider (quadrature)
# Strata per noise component (psi0, zeta0, xdot, ydot) of a jump, by regime. With the pitch drifting
# the walk's lattice decides failures and two velocity strata give the same MFPT as four (zeta0 0.90
# and 0.96: 298.6 and 92.7 either way, four times the time); without drift failures are rare and
# come from the velocity noise's tails, which need eight (velocity 0.08: 7,924 with 8 strata not
# widened, 5,959 widened, Monte-Carlo 5,978).
DRIFT_STRATA = (3, 2, 2, 2)
STILL_STRATA = (3, 2, 8, 8)
PITCH_STEP_SIGMAS = 4.0  # the pitch step's stencil reaches this many standard deviations


@dataclass(frozen=True)
class ChainGrid:
    """How fine the chain is. The defaults reproduce Monte-Carlo MJTF within a few per cent
    at the Fig. 11 levels (docs/analyses.md); :func:`refined` makes the next finer grid.

    Attributes:
        velocity_nodes: nodes per velocity axis across the core (the uniform part).
        pitch_spacing: the pitch nodes' spacing in standard deviations of the pitch step.
        strata: strata per noise component of a jump (psi0, zeta0, xdot, ydot), their product
            the jumps run from each state (:func:`quadrature`); None: :data:`DRIFT_STRATA` with
            the pitch drifting, :data:`STILL_STRATA` without (:meth:`strata_for`).
        margin: nodes kept around those noisy paths visited (each axis, pitch included).
        half_width: the velocity window's half-width around the paths' median [sqrt(g l0)].
        paths, path_jumps: the noisy paths that find the core (each until it fails or
            reaches ``path_jumps``).
        max_pairs: the most (velocity node, pitch) pairs whose jumps are run: the chain's
            compute, refused past it (the service sets a smaller one than a script).
    """

    velocity_nodes: int = 30
    pitch_spacing: float = 0.5
    strata: tuple[int, int, int, int] | None = None
    margin: int = 2
    half_width: float = DEFAULT_HALF_WIDTH
    paths: int = 400
    path_jumps: int = 3000
    max_pairs: int = MAX_PAIRS

    def __post_init__(self) -> None:
        for field, low, high in (
            ("velocity_nodes", 4, 400),
            ("margin", 0, 20),
            ("paths", 10, 100_000),
            ("path_jumps", 10, 1_000_000),
            ("max_pairs", 100, MAX_PAIRS),
        ):
            value = getattr(self, field)
            if isinstance(value, bool) or int(value) != value or not low <= value <= high:
                raise ParameterError(f"grid.{field}", f"must be an integer in [{low}, {high}], got {value!r}")
        if self.strata is not None:
            strata = tuple(self.strata)
            if len(strata) != 4 or any(isinstance(v, bool) or int(v) != v or not 1 <= v <= 16 for v in strata):
                raise ParameterError("grid.strata", f"must be 4 integers in [1, 16], got {self.strata!r}")
            object.__setattr__(self, "strata", tuple(int(v) for v in strata))
        if self.paths * self.path_jumps > MAX_PATH_JUMPS:
            raise ParameterError(
                "grid.path_jumps",
                f"paths x path_jumps must be at most {MAX_PATH_JUMPS:,} (their draws are held at once), "
                f"got {self.paths} x {self.path_jumps}",
            )
        check_range("grid.pitch_spacing", self.pitch_spacing, 0.05, 4.0, low_open=False, high_open=False)
        check_range("grid.half_width", self.half_width, 0.05, 10.0, low_open=False, high_open=False)

    def refined(self, factor: float = math.sqrt(2.0)) -> ChainGrid:
        """The next grid: ``factor`` times the velocity nodes, the pitch spacing over ``factor``
        (each kept within its range)."""
        return replace(
            self,
            velocity_nodes=min(400, max(4, round(self.velocity_nodes * factor))),
            pitch_spacing=min(4.0, max(0.05, self.pitch_spacing / factor)),
        )

    def strata_for(self, pitch_drifts: bool) -> tuple[int, int, int, int]:
        """The strata this grid uses: its own, or the regime's default."""
        if self.strata is not None:
            return self.strata
        return DRIFT_STRATA if pitch_drifts else STILL_STRATA

    def worst_case_jumps(self, pitch_drifts: bool) -> int:
        """The jumps :func:`sim_core.robustness.mfpt.mfpt` runs at most: both grids' pairs at their limit,
        each with every draw of the rule, and both grids' exploring paths to their end."""
        draws = math.prod(self.strata_for(pitch_drifts))
        return 2 * (self.max_pairs * draws + self.paths * self.path_jumps)

    def to_dict(self) -> dict:
        return asdict(self)


def quadrature(sigmas, points, widen: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A product rule for independent zero-mean Gaussians of standard deviations ``sigmas``:
    ``(draws (S, len(sigmas)), weights (S,))``, with the Gaussian's mean and variance.

    Each component takes ``points`` (one count, or one per component) strata, each at its
    conditional mean with its probability as weight, the positions then scaled so that their
    variance is the Gaussian's. The strata are equiprobable for a Gaussian ``widen`` times wider,
    so the outer ones reach into the tails: where the chain's failures are rare they come from
    the noise's tails, and equiprobable strata (whose outermost point of 16 sits at 1.9 sigma)
    made the MFPT at velocity noise 0.08 1.2-2.8 times Monte-Carlo's. Not Gauss–Hermite either:
    whether a jump fails is a threshold in the noise, and a 3-point Hermite rule puts 1/6 of the
    mass at 1.7 sigma, a 1-in-15 failure made 1-in-6. A zero sigma takes one point, at 0."""
    from scipy.special import ndtr, ndtri

    widen = TAIL_WIDENING if widen is None else widen
    counts = np.broadcast_to(np.asarray(points, dtype=np.int64), (len(sigmas),))
    axes, masses = [], []
    for sigma, count in zip(sigmas, counts, strict=True):
        if sigma == 0.0 or count == 1:
            axes.append(np.zeros(1))
            masses.append(np.ones(1))
            continue
        edges = widen * ndtri(np.arange(count + 1) / count)  # -inf ... inf
        mass = ndtr(edges[1:]) - ndtr(edges[:-1])
        density = np.exp(-0.5 * np.square(edges)) / math.sqrt(2.0 * math.pi)
        means = (density[:-1] - density[1:]) / mass
        means -= mass @ means  # exactly zero-mean against rounding
        axes.append(sigma * means / math.sqrt(mass @ np.square(means)))
        masses.append(mass)
    grids = np.meshgrid(*axes, indexing="ij")
    weight_grids = np.meshgrid(*masses, indexing="ij")
    draws = np.stack([grid.ravel() for grid in grids], axis=1)
    weights = np.prod(np.stack([grid.ravel() for grid in weight_grids], axis=1), axis=1)
    return draws, weights / weights.sum()


def pitch_stencil(sigma: float, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """The pitch step on the nodes: offsets (whole nodes) and their probabilities, a discrete
    Gaussian of standard deviation ``sigma`` on nodes ``spacing`` apart [rad]."""
    if sigma == 0.0:
        return np.zeros(1, dtype=np.int64), np.ones(1)
    reach = max(1, math.ceil(PITCH_STEP_SIGMAS * sigma / spacing))
    offsets = np.arange(-reach, reach + 1)
    weights = np.exp(-0.5 * (offsets * spacing / sigma) ** 2)
    return offsets.astype(np.int64), weights / weights.sum()


def velocity_axis(values: np.ndarray, nodes: int, center: float, half_width: float, floor: float) -> np.ndarray:
    """One velocity axis: ``nodes`` uniform nodes over the core (the central 99% of ``values``,
    widened by 10% each side), then nodes ``TAIL_GROWTH`` times further apart each out to the
    window ``center ± half_width`` (cut at ``floor``). The core is where paths spend 90% of their
    time, not all of it: widened to their extremes, a level whose pitch wanders far (zeta0 0.96)
    spread 30 nodes 0.08 apart and its MFPT came out half Monte-Carlo's."""
    low, high = np.percentile(values, CORE_PERCENTILES)
    pad = 0.1 * max(high - low, 1e-3)
    window = (max(center - half_width, floor), center + half_width)
    low, high = max(low - pad, window[0]), min(high + pad, window[1])
    core = np.linspace(low, high, nodes)
    spacing = core[1] - core[0]
    below, above = [], []
    step, at = spacing, low
    while at > window[0]:
        step *= TAIL_GROWTH
        at = max(at - step, window[0])
        below.append(at)
    step, at = spacing, high
    while at < window[1]:
        step *= TAIL_GROWTH
        at = min(at + step, window[1])
        above.append(at)
    return np.concatenate([below[::-1], core, above])


def pitch_axis(visited_pitch: np.ndarray, sigma: float, spacing: float) -> np.ndarray:
    """Pitch nodes ``(i - c) spacing`` [rad], symmetric about 0 and reaching past the largest
    pitch the paths visited by a few steps' standard deviations; one node (0) without drift."""
    if sigma == 0.0:
        return np.zeros(1)
    reach = float(np.max(np.abs(visited_pitch))) if visited_pitch.size else 0.0
    half = math.ceil((reach + PITCH_STEP_SIGMAS * sigma) / spacing)
    return np.arange(-half, half + 1) * spacing


def kept_states(
    visited: np.ndarray, xdots: np.ndarray, ydots: np.ndarray, pitches: np.ndarray, margin: int
) -> np.ndarray:
    """Which nodes are states of the chain, (layers, ny, nx) booleans: the corners of every cell
    a path visited on its nearest pitch layer, grown by ``margin`` nodes along each axis. One
    pitch layer (no drift) keeps every node: rare excursions then decide the MFPT, and paths of
    typical length never visit where they go."""
    layers, ny, nx = pitches.size, ydots.size, xdots.size
    if layers == 1:
        return np.ones((1, ny, nx), dtype=bool)
    from scipy.ndimage import binary_dilation

    mask = np.zeros((layers, ny, nx), dtype=bool)
    spacing = pitches[1] - pitches[0]
    layer = np.rint(visited[:, 2] / spacing).astype(np.int64) + (layers - 1) // 2
    ix = np.searchsorted(xdots, visited[:, 0], side="right") - 1
    iy = np.searchsorted(ydots, visited[:, 1], side="right") - 1
    inside = (ix >= 0) & (ix < nx - 1) & (iy >= 0) & (iy < ny - 1) & (layer >= 0) & (layer < layers)
    layer, ix, iy = layer[inside], ix[inside], iy[inside]
    for dy in (0, 1):
        for dx in (0, 1):
            mask[layer, iy + dy, ix + dx] = True
    if margin:
        mask = binary_dilation(mask, structure=np.ones((3, 3, 3), dtype=bool), iterations=margin)
    return mask


def check_states(count: int) -> None:
    if count > MAX_STATES:
        raise ParameterError(
            "grid",
            f"the chain would have {count:,} states, more than the {MAX_STATES:,} this machine's memory allows; "
            "use fewer velocity nodes or a wider pitch spacing",
        )


def check_pairs(count: int, limit: int) -> None:
    if count > limit:
        raise ParameterError(
            "grid",
            f"the chain would run the jumps of {count:,} (velocity node, pitch) pairs, more than the {limit:,} "
            "allowed; use fewer velocity nodes or a wider pitch spacing",
        )
