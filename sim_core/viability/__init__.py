"""Viability kernels over state x action grids (sheim/vibly's semantics, cell for cell): the engine, its grids
and kernels, the ParkourBot's step map on the section, the guard a controller keeps inside the kernel, and
vibly's SLIP hopper to cross-check the engine (docs/analyses.md).
"""
