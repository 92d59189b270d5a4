"""Worlds through the client: store one (the §8 JSON, a named world, or random footholds from a
seed), list, read back as posted, rename, delete. The part of :class:`parkourlab.Client` that deals
with ``/api/v1/worlds`` (docs/worlds.md, "Worlds in the service")."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import TYPE_CHECKING, Any

from parkourlab.bodies import mapping, present
from parkourlab.types import World

if TYPE_CHECKING:
    from parkourlab._http import Http

DEFAULT_PAGE_SIZE = 50


class WorldCalls:
    """World calls, mixed into :class:`parkourlab.Client` (which provides ``_http``)."""

    _http: Http

    def create_world(
        self,
        name: str,
        *,
        world: Mapping[str, Any] | None = None,
        named: str | None = None,
        random: Mapping[str, Any] | None = None,
        preset: str | None = None,
    ) -> World:
        """Store a world as ``name`` from exactly one of: ``world`` (a world file's JSON,
        docs/model.md §8 — e.g. ``json.load`` of one), ``named`` (``"staircase"``, ...) or ``random``
        (``{"seed": 7, "holds": 12, ...}``, ``parkour world random``'s options). ``preset``: the
        robot whose leg length converts a world in metres (default ``paper``). A malformed world
        raises :class:`~parkourlab.InvalidRequest` naming the side and point or segment."""
        body = {"name": name, "world": mapping(world), "named": named, "random": mapping(random), "preset": preset}
        return self._http.call("POST", "/api/v1/worlds", body=present(body))

    def worlds(self, *, page_size: int = DEFAULT_PAGE_SIZE) -> Iterator[World]:
        """Every stored world, newest first, page after page."""
        return self._http.pages("/api/v1/worlds", {}, page_size)

    def world(self, world_id: int) -> World:
        """A stored world; its ``world`` is the §8 JSON exactly as it was posted."""
        return self._http.call("GET", f"/api/v1/worlds/{world_id}")

    def rename_world(self, world_id: int, name: str) -> World:
        return self._http.call("PATCH", f"/api/v1/worlds/{world_id}", body={"name": name})

    def delete_world(self, world_id: int) -> None:
        """Delete a world; :class:`~parkourlab.Conflict` (naming one) while a run or job uses it."""
        self._http.call("DELETE", f"/api/v1/worlds/{world_id}")
