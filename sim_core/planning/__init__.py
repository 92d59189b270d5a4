"""Foot placement in a world: plans from foothold to foothold (docs/model.md §8; the paper's "while
controlling foot placement"). :mod:`sim_core.planning.planner` searches the legs' commands jump
by jump for the most robust way to a goal height under the noise of docs/model.md §5.1."""
