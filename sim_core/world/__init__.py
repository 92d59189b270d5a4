"""Worlds beyond two parallel walls: sides as polylines with friction, footholds at orientations
(docs/model.md §8). :mod:`sim_core.world.world` holds the data; the compiled stride between
sides is :mod:`sim_core.world.stride`, the validated climb :mod:`sim_core.world.climb`."""
