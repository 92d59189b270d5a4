"""Viability kernels and their measure over state x action grids (Heim & Sprowitz's sense;
the reference implementation is sheim/vibly, whose semantics this engine keeps cell for cell).

A *step map* is passed in, so the engine works for any model: the ParkourBot's own map on its
mid-chute section (:mod:`sim_core.viability.step_map`), a calibrated preset's, or vibly's SLIP
hopper (:mod:`sim_core.viability.slip_hopper`, the cross-check). Its shape::

    step_map(states (N, ds) float64, actions (N, da) float64)
        -> (next_states (N, ds), failed (N,) bool[, done (N,) bool])

one step for each row; ``done`` (optional) marks a step that reached the map's goal — a world's
top, where the chute is climbed — viable whatever follows (its bins are :data:`DONE`). Over a
:class:`ViabilityGrid` of state and action axes the engine

1. maps every (state, action) grid pair once (the *transition map*): failed, or the bin of the
   state reached, ``np.digitize(next, axis)`` per dimension (``0 .. n``: below the first node,
   between nodes ``i - 1`` and ``i``, past the last), the grid closed: a state reached exactly
   on an axis' last node is in the last bin, not past it (``np.digitize`` alone puts it outside,
   which only an axis the map carries over unchanged meets, as the ParkourBot's pitch; on
   another axis it has measure zero);
2. shrinks the viable set to its greatest fixed point: a pair is viable while it does not fail
   and every grid node at the corners of the bin it reaches is in the kernel. The kernel is
   the set of states with at least one viable action. This is vibly's ``compute_QV``:
   conservative, since the state reached must be surrounded by viable nodes, not merely near
   one. A state reached beyond the grid is not viable (nothing is known there); with
   ``edges_extend`` it is judged by the edge nodes beside it, as vibly does (and, as vibly,
   the bin below every axis then counts as failed: vibly's transition map stores failure as
   bin 0);
3. the *measure* of a state is the fraction of its actions that are viable (vibly's ``S_M``),
   and a pair's measure is the mean measure of the nodes around the state it reaches
   (vibly's ``Q_M``): how much room for error the next step leaves.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from sim_core.chunks import Progress, chunk_slices
from sim_core.model.validation import ParameterError
from sim_core.viability.grid import ViabilityGrid
from sim_core.viability.kernels import pair_measures, shrink

__all__ = ["FAILED", "StepMap", "Viability", "ViabilityGrid", "compute_viability", "transition_map"]
__all__ += ["viability_of_map"]

StepMap = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, ...]]
FAILED = -1  # the bin of a failed pair
DONE = -2  # the bin of a pair that reached the step map's goal (a world's top): viable, whatever follows
DEFAULT_CHUNK_PAIRS = 200_000  # ~0.5 s of the paper model's stances on two cores: steady progress


@dataclass(frozen=True)
class Viability:
    """The kernel and measure on one grid; arrays in the grid's shape (state axes, then action axes).

    Attributes:
        failed: bool, where the step itself fails.
        bins: int, shape + (ds,), the bin each pair reaches per state dimension; -1 where failed,
            -2 (DONE) where it reached the step map's goal.
        viable_pairs: bool, the viable state-action pairs (vibly's ``Q_V``).
        kernel: bool, state shape: the viability kernel (``S_V``).
        measure: float, state shape: the fraction of a state's actions that are viable (``S_M``).
        pair_measure: float: the mean measure of the nodes around the state a viable pair
            reaches, 0 elsewhere (``Q_M``).
        sweeps: the passes until the viable set stopped shrinking.
        seconds_map, seconds_kernel: the time of the transition map and of the fixed point.
    """

    grid: ViabilityGrid
    failed: np.ndarray
    bins: np.ndarray
    viable_pairs: np.ndarray
    kernel: np.ndarray
    measure: np.ndarray
    pair_measure: np.ndarray
    sweeps: int
    seconds_map: float
    seconds_kernel: float

    @property
    def kernel_fraction(self) -> float:
        return float(np.mean(self.kernel))

    def nearest_node(self, state) -> tuple[int, ...]:
        """The index of the state node nearest ``state``, axis by axis."""
        values = np.asarray(state, dtype=np.float64).ravel()
        if values.size != len(self.grid.state_axes):
            raise ParameterError("state", f"must have {len(self.grid.state_axes)} components, got {values.size}")
        axes = self.grid.state_axes
        return tuple(int(np.argmin(np.abs(axis - value))) for axis, value in zip(axes, values, strict=True))

    def viable_actions(self, state_index: tuple[int, ...]) -> np.ndarray:
        """The viable actions of one state node, as action values (rows of ``grid.actions()``)."""
        mask = self.viable_pairs[tuple(state_index)].ravel()
        return self.grid.actions()[mask]

    def to_dict(self, *, include_grids: bool = True) -> dict:
        """The figures of the kernel, with the kernel and measure over the state nodes."""
        in_kernel = self.measure[self.kernel]
        result = {
            "kernel_fraction": self.kernel_fraction,
            "kernel_cells": int(np.count_nonzero(self.kernel)),
            "cells": int(self.kernel.size),
            "pairs": self.grid.pairs,
            "viable_pair_fraction": float(np.mean(self.viable_pairs)),
            "failed_pair_fraction": float(np.mean(self.failed)),
            "measure_mean": float(in_kernel.mean()) if in_kernel.size else 0.0,
            "sweeps": self.sweeps,
            "seconds": self.seconds_map + self.seconds_kernel,
            "seconds_map": self.seconds_map,
            "seconds_kernel": self.seconds_kernel,
        }
        if include_grids:
            result["kernel"] = self.kernel.tolist()
            result["measure"] = self.measure.tolist()
        return result


def transition_map(
    step_map: StepMap,
    grid: ViabilityGrid,
    *,
    chunk_pairs: int = DEFAULT_CHUNK_PAIRS,
    progress: Progress | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """``(failed, bins)`` of every grid pair (see :class:`Viability`), ``step_map`` run in chunks
    of ``chunk_pairs`` pairs with ``progress(done, total)`` after each."""
    states, actions = grid.states(), grid.actions()
    count, dimensions = grid.pairs, len(grid.state_axes)
    failed = np.empty(count, dtype=bool)
    bins = np.empty((count, dimensions), dtype=np.int64)
    slices = chunk_slices(count, chunk_pairs)
    for done, part in enumerate(slices, start=1):
        pair = np.arange(part.start, part.stop)  # state-major: pair = state * actions + action
        stepped = step_map(states[pair // actions.shape[0]], actions[pair % actions.shape[0]])
        reached = np.asarray(stepped[0], dtype=np.float64).reshape(-1, dimensions)
        part_failed = np.asarray(stepped[1], dtype=bool) | ~np.all(np.isfinite(reached), axis=1)
        part_done = np.zeros(part_failed.shape, dtype=bool) if len(stepped) < 3 else np.asarray(stepped[2], dtype=bool)
        part_done &= ~part_failed
        failed[part] = part_failed
        for d, axis in enumerate(grid.state_axes):
            found = closed_bins(np.nan_to_num(reached[:, d]), axis)
            bins[part, d] = np.where(part_failed, FAILED, np.where(part_done, DONE, found))
        if progress is not None:
            progress(done, len(slices))
    return failed.reshape(grid.shape), bins.reshape((*grid.shape, dimensions))


def closed_bins(values: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """``np.digitize(values, axis)``, a value on the last node in the last bin."""
    bins = np.digitize(values, axis)
    bins[values == axis[-1]] = axis.size - 1
    return bins


def viability_of_map(
    grid: ViabilityGrid, failed: np.ndarray, bins: np.ndarray, *, edges_extend: bool = False
) -> Viability:
    """The kernel, viable pairs and measures from a transition map (:func:`transition_map`);
    ``edges_extend`` as in the module docstring."""
    started = time.perf_counter()
    state_shape = np.asarray(grid.state_shape, dtype=np.int64)
    states = int(np.prod(state_shape))
    actions = int(np.prod(grid.action_shape))
    flat_bins = np.ascontiguousarray(bins.reshape(states * actions, -1))
    viable = ~failed.reshape(states * actions)
    done = flat_bins[:, 0] == DONE  # no corner of a DONE bin is a node: the shrink never drops it
    if edges_extend:
        viable &= np.any(flat_bins != 0, axis=1)
    else:
        viable &= np.all((flat_bins >= 1) & (flat_bins <= state_shape - 1), axis=1) | done
    viable = np.ascontiguousarray(viable)
    kernel_mask = np.empty(states, dtype=bool)
    sweeps = shrink(flat_bins, viable, kernel_mask, state_shape, actions)
    measure = viable.reshape(states, actions).mean(axis=1)
    pair_measure = np.zeros(states * actions)
    pair_measures(flat_bins, viable, measure, state_shape, pair_measure)
    pair_measure[done] = 1.0  # the goal leaves all the room there is
    shape = grid.shape
    return Viability(
        grid=grid,
        failed=failed,
        bins=bins,
        viable_pairs=viable.reshape(shape),
        kernel=kernel_mask.reshape(grid.state_shape),
        measure=measure.reshape(grid.state_shape),
        pair_measure=pair_measure.reshape(shape),
        sweeps=sweeps,
        seconds_map=0.0,
        seconds_kernel=time.perf_counter() - started,
    )


def compute_viability(
    step_map: StepMap,
    grid: ViabilityGrid,
    *,
    edges_extend: bool = False,
    chunk_pairs: int = DEFAULT_CHUNK_PAIRS,
    progress: Progress | None = None,
) -> Viability:
    """The viability kernel and measure of ``step_map`` on ``grid`` (module docstring)."""
    started = time.perf_counter()
    failed, bins = transition_map(step_map, grid, chunk_pairs=chunk_pairs, progress=progress)
    seconds_map = time.perf_counter() - started
    result = viability_of_map(grid, failed, bins, edges_extend=edges_extend)
    return Viability(**{**result.__dict__, "seconds_map": seconds_map})
