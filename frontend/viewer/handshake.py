"""What the 3D view learns from a browser's websocket handshake: whether its page may connect at
all (its Origin) and which control panel it belongs to (its path).

Origins. A page from anywhere else that the lab's browser opens (another site, a DNS-rebinding one) could
otherwise connect to ``ws://localhost:8001`` — a browser sends the page's ``Origin`` but leaves
the check to the server — and read the scene (the robot's live pose) or drive the shared GUI. The
rule is the service's own (``backend.api.security.origin_allowed``): an Origin whose host is on
the allow-list, over http or https, any port; no Origin at all (a client that is not a browser)
is allowed.

viser 1.1.1 has no hook for its websocket handshake: ``WebsockServer._background_worker`` calls
``websockets.asyncio.server.serve`` with its own ``process_request`` (the static-file handler, a
closure) and neither ``origins=`` nor ``process_response``, and ``ViserServer.__init__`` starts
that server before it returns. What it does offer is ``WebsockServer.on_client_connect``: its
callbacks run right after the handshake, before viser sends the client anything or reads a
message from it, and the handshake's request is on the connection viser keeps per client
(``_live_connections``). So the check runs there, and a connection from a foreign Origin is
closed (1008, policy violation) with nothing exchanged. The handshake itself has succeeded by
then (the browser sees an open socket, then the close), and the names used are viser's private
ones, read through :mod:`frontend.viewer.viser_adapter`: :func:`refuse_foreign_origins` fails
loudly, and the view does not start, if they are gone.

Viewer ids. The control panel embeds the view with ``?websocket=ws://HOST:PORT/viewer/ID`` (viser's
client connects to the address in its ``websocket`` parameter, path included), ``ID`` a random
id the panel made for itself. The path is on the handshake's request, so the view knows which
panel each browser's view belongs to (:func:`viewer_of`), and History → "3D" in one panel opens
the replay in that panel's view only. A view opened any other way has no id: it is nobody's to
switch from outside.
"""

from __future__ import annotations

import asyncio
import logging
import re
from collections.abc import Iterable

import viser

from backend.api.security import origin_allowed
from backend.schemas.view import VIEWER_ID_PATTERN
from backend.settings import host_name
from frontend.viewer.viser_adapter import event_loop, live_connections, websocket_server

log = logging.getLogger("parkourlab.view")
POLICY_VIOLATION = 1008
VIEWER_PATH = re.compile(rf"/viewer/({VIEWER_ID_PATTERN.strip('^$')})/?")


def viewer_of(server: viser.ViserServer, client: viser.ClientHandle) -> str | None:
    """The viewer id in ``client``'s websocket path (``/viewer/ID``), or None (any other path, or
    a connection already gone)."""
    connection = live_connections(server).get(client.client_id)
    if connection is None:
        return None
    match = VIEWER_PATH.fullmatch(connection.request.path.partition("?")[0])
    return None if match is None else match.group(1)


def refuse_foreign_origins(server: viser.ViserServer, allowed_hosts: Iterable[str]) -> None:
    """Close every websocket of ``server`` whose Origin is not an allowed host, from now on and
    any already open (the server was listening before this could be installed)."""
    allowed = frozenset(host_name(host) for host in allowed_hosts)
    live = live_connections(server)
    websock = websocket_server(server)

    def foreign(connection) -> str | None:
        origin = connection.request.headers.get("Origin")
        return origin if origin is not None and not origin_allowed(origin, allowed) else None

    async def check(client) -> None:
        connection = live[client.client_id]  # a KeyError here closes the connection too (1011)
        if (origin := foreign(connection)) is not None:
            log.warning("3D view: refused a websocket from origin %.200r", origin)
            await connection.close(POLICY_VIOLATION, "origin not allowed")

    websock.on_client_connect(check)
    loop = event_loop(server)
    for connection in list(live.values()):
        if foreign(connection) is not None and loop is not None:
            asyncio.run_coroutine_threadsafe(connection.close(POLICY_VIOLATION, "origin not allowed"), loop)
