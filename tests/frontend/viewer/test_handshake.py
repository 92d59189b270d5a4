"""What the 3D view reads from a websocket's handshake (frontend/viewer/handshake.py): pages of
foreign origins are refused, and a panel's view is known by the viewer id in its path. A real
viser server, with a websocket client as a browser's would connect (viser's subprotocol, an Origin)."""

import time

import pytest
import viser
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from backend.settings import LOOPBACK_HOSTS
from frontend.viewer.handshake import POLICY_VIOLATION, refuse_foreign_origins, viewer_of
from tests.frontend.viewer.headless import HeadlessViewer


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


@pytest.mark.parametrize(
    ("path", "viewer"),
    [("/viewer/panel-1234", "panel-1234"), ("/viewer/panel-1234/", "panel-1234"), ("/", None),
     ("/viewer/short", None), ("/viewer/../../x", None), ("/elsewhere/panel-1234", None)],
)  # fmt: skip
def test_a_browser_s_view_is_known_by_its_panel_s_viewer_id_from_the_websocket_path(path, viewer):
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    found = []
    server.on_client_connect(lambda client: found.append(viewer_of(server, client)))
    try:
        with HeadlessViewer(server.get_port(), path=path):
            deadline = time.monotonic() + 10
            while not found and time.monotonic() < deadline:
                time.sleep(0.02)
        assert found == [viewer]
    finally:
        server.stop()
