"""What a gait atlas computes over, light (no kernels) so that request schemas and plans read it:
the start states of each cell's orbits, how long they settle, the longest cycle counted as a gait
and the most cells an atlas takes (:mod:`sim_core.section.atlas` computes it)."""

from __future__ import annotations

MAX_PERIOD = 8  # [jumps]: longer cycles (or chaos) count as "no periodic gait"
TRANSIENT_JUMPS = 300
DEFAULT_STARTS = ((-0.9, -0.2), (-0.6, 0.5), (-1.4, -0.8), (-1.2, 0.8))  # [sqrt(g l0)]
MAX_CELLS = 40_000
