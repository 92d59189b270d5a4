"""A UDP relay between a tracker stream (the virtual robot's camera) and the service, that the
test can silence: the tracker stopping mid-run, as a camera, its software or a switch would.

``rewrite``: a function applied to each datagram forwarded (e.g. a NatNet frame re-encoded without
the robot's rigid body: the tracker streaming on, but blind to the robot)."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Callable


class TrackerRelay:
    def __init__(self, to: tuple[str, int]):
        self.to = to
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.bind(("127.0.0.1", 0))
        self.socket.settimeout(0.02)
        self.port = self.socket.getsockname()[1]
        self.forwarded = 0
        self.last_forwarded: float | None = None  # time.monotonic() of the last datagram forwarded
        self.rewrite: Callable[[bytes], bytes] | None = None
        self._forwarding = threading.Event()
        self._forwarding.set()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._relay, name="tracker-relay", daemon=True)

    def start(self) -> TrackerRelay:
        self._thread.start()
        return self

    def silence(self) -> None:
        """Stop forwarding (the tracker goes silent); datagrams that arrive meanwhile are lost."""
        self._forwarding.clear()

    def resume(self) -> None:
        self._forwarding.set()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)
        self.socket.close()

    def _relay(self) -> None:
        while not self._stop.is_set():
            try:
                data = self.socket.recv(65536)
            except TimeoutError:
                continue
            except OSError:
                return
            if not self._forwarding.is_set():
                continue
            rewrite = self.rewrite
            self.socket.sendto(rewrite(data) if rewrite is not None else data, self.to)
            self.forwarded += 1
            self.last_forwarded = time.monotonic()
