"""What the planner asks of a landing, vectorised: the draws of the noise it runs each candidate
under, the leg a body stands on under them, whether a touchdown holds and whether it keeps the
placement law's margins (:mod:`sim_core.planning.planner`)."""

from __future__ import annotations

import math

import numpy as np

from sim_core.control.laws.placement import PlacementSettings
from sim_core.control.placement import leg_on_wall
from sim_core.model.noise import NoiseModel


def noise_draws(noise: NoiseModel, samples: int, seed: int) -> np.ndarray:
    """(samples + 1, 5) draws of noise — the coming leg's (psi0, zeta0), the velocity (xdot, ydot)
    at this touchdown and the zeta0 this leg stands on — row 0 the nominal (zeros)."""
    record = noise.record()
    sigma_psi0 = math.hypot(record.sigma_psi0, record.sigma_pitch)  # the pitch's step turns the leg too
    scale = np.array([sigma_psi0, record.sigma_zeta0, record.sigma_velocity, record.sigma_velocity,
                      record.sigma_zeta0])  # fmt: skip
    normal = np.random.default_rng(seed).standard_normal((samples, 5))
    return np.vstack([np.zeros(5), normal * scale])


def standing_legs(sides, node, draws) -> np.ndarray:
    """The leg ``node`` stands on under each draw: its length as drawn, its angle the one that keeps
    the foot on the wall below the body (the law sees the body, not the leg's noise:
    :func:`sim_core.control.placement.leg_on_wall`)."""
    x, y = node.row[0], node.row[1]
    legs = np.empty((len(draws), 2))
    for d, draw in enumerate(draws):
        zeta0 = node.leg[1] + draw[4]
        legs[d] = leg_on_wall(sides, node.side, x, y, node.leg[0], zeta0), zeta0
    return legs


def with_margins(sides, side, segment, foot_y, psi0, settings: PlacementSettings) -> np.ndarray:
    """Whether feet at ``foot_y`` [l0] set down at ``psi0`` [rad] on ``side``'s ``segment`` keep the
    placement law's margins (:mod:`sim_core.control.placement`: from the foothold's ends, a quarter
    of its length at most, and inside its cone, half of it at most), so the law can follow."""
    last = sides.counts[side] - 1
    inner = np.clip(segment, 0, np.maximum(last - 1, 0))
    low, high = sides.points[side, inner], sides.points[side, inner + 1]
    length = np.hypot(*(high - low).T)
    share = (foot_y - low[:, 1]) / np.maximum(high[:, 1] - low[:, 1], 1e-300)
    along = np.minimum(share, 1.0 - share) * length
    along = np.where(segment < 0, sides.points[side, 0, 1] - foot_y, along)
    along = np.where(segment >= last, foot_y - sides.points[side, last, 1], along)
    asked = np.where((segment < 0) | (segment >= last), settings.end_margin, np.minimum(settings.end_margin,
                                                                                        0.25 * length))  # fmt: skip
    column = np.clip(segment + 1, 0, sides.beta.shape[1] - 1)
    half = np.arctan(sides.friction[side, column])
    cone = half - np.abs(psi0 - sides.beta[side, column])
    return (along >= asked) & (cone >= np.minimum(math.radians(settings.cone_margin_deg), 0.5 * half))


def in_cone(sides, side, segment, psi0) -> np.ndarray:
    """Whether a touchdown at ``psi0`` [rad] on ``side``'s ``segment`` holds at once (docs/model.md §8)."""
    column = np.clip(segment + 1, 0, sides.beta.shape[1] - 1)
    beta, mu = sides.beta[side, column], sides.friction[side, column]
    return np.abs(psi0 - beta) < np.arctan(mu)
