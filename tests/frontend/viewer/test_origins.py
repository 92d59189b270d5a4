"""The 3D view's websocket refuses pages of foreign origins (frontend/viewer/origins.py), on a real
viser server, with a websocket client as a browser's would connect (viser's subprotocol, an Origin)."""

import pytest
import viser
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from backend.settings import LOOPBACK_HOSTS
from frontend.viewer.origins import POLICY_VIOLATION, refuse_foreign_origins


@pytest.fixture(scope="module")
def view_url():
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    refuse_foreign_origins(server, (*LOOPBACK_HOSTS, "lab-pc.example"))
    server.scene.add_frame("/robot")  # something to send a client that is let in
    yield f"ws://127.0.0.1:{server.get_port()}/"
    server.stop()


def _first_message(url: str, origin: str | None):
    with connect(url, origin=origin, subprotocols=[f"viser-v{viser.__version__}"], open_timeout=10) as socket:
        return socket.recv(timeout=10)


@pytest.mark.parametrize("origin", ["http://evil.example", "http://evil.example:8001", "null", "http://127.0.0.2:8001"])
def test_a_page_of_a_foreign_origin_is_refused_before_anything_is_sent(view_url, origin):
    with pytest.raises(ConnectionClosed) as closed:
        _first_message(view_url, origin)
    assert closed.value.rcvd is not None and closed.value.rcvd.code == POLICY_VIOLATION


@pytest.mark.parametrize("origin", [None, "http://127.0.0.1:8000", "http://localhost:8001", "https://lab-pc.example"])
def test_the_panel_s_origins_and_clients_without_one_get_the_scene(view_url, origin):
    assert _first_message(view_url, origin)


def test_a_viser_without_the_per_client_connections_is_not_started_unchecked():
    class Changed:  # what a viser whose internals moved would look like to the check
        _websock_server = object()

    with pytest.raises(RuntimeError, match="Origins"):
        refuse_foreign_origins(Changed(), LOOPBACK_HOSTS)
