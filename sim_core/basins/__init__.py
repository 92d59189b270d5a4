"""Basins of attraction on the section, and energy sweeps: a gait followed over zeta0 with its basin
(paper Figs. 6-8, docs/analyses.md). :mod:`.grid` (the grids' defaults) stays light for the CLI.
"""
