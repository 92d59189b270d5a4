"""The link's one owner: a thread that alone opens, reconnects and closes the service's :class:`RobotLink`.

Everything else sends it requests on a queue (the actor pattern) and, where it needs one, waits for
the answer: :meth:`LinkSupervisor.connect` and :meth:`~LinkSupervisor.disconnect` from the API,
:meth:`~LinkSupervisor.close` at service shutdown, and the link's own "lost" notification, which only
puts a request on the queue — a lost link starts no thread. So no two connects, closes or reconnects
of one link ever overlap, by construction.

A lost link is retried while it is wanted: at once, then every ``retry_period`` [s] until the robot
answers again, a disconnect by hand, or shutdown. An attempt is bounded (``retry_period`` for the
robot's first telemetry, plus closing what is left), and requests that arrive during it wait for it
to end. Nobody else may call the link's ``connect``, ``reconnect`` or ``close``; reading the link and
sending it commands (arm, set_leg, the e-stop) needs no request: those are the link's own, bounded.

A connect by hand that fails never drops a working link: one on another port stays open until the
new link answers; one on the same port (which two links cannot share) gives way and is reopened.

Every ending the supervisor sees disarms: before it closes a live link (a disconnect, a connect to
another, shutdown), and when a lost link comes back, it sends DISARM and waits for telemetry to
confirm it (:meth:`RobotLink.make_safe`), whatever the link believed the robot's state to be.
"""

from __future__ import annotations

import concurrent.futures
import functools
import logging
import os
import queue
import threading
import time
from dataclasses import dataclass, field

from backend.robot.link import LinkError, LinkState, RobotLink

log = logging.getLogger("parkourlab.robot")

RETRY_PERIOD = 1.0  # [s] between reconnect attempts on a dropped link
CONNECT_TIMEOUT = 3.0  # [s] for the robot's first telemetry on a connect by hand
ANSWER_TIMEOUT = 15.0  # [s] the longest a request waits: a connect and two bounded closes, with room


@dataclass(frozen=True)
class Connect:
    """Close the current link (if any), then open ``link``; answered with its state or a LinkError."""

    link: RobotLink
    timeout: float
    answer: concurrent.futures.Future = field(default_factory=concurrent.futures.Future)


@dataclass(frozen=True)
class Disconnect:
    """Close the current link and stop retrying it; answered with None."""

    answer: concurrent.futures.Future = field(default_factory=concurrent.futures.Future)


@dataclass(frozen=True)
class Lost:
    """``link`` says it is down (its reader saw silence or a read error); not answered."""

    link: RobotLink
    reason: str


@dataclass(frozen=True)
class Shutdown:
    """Close the current link and end the thread; answered with None."""

    answer: concurrent.futures.Future = field(default_factory=concurrent.futures.Future)


Request = Connect | Disconnect | Lost | Shutdown


class LinkSupervisor:
    """The one thread that opens, reconnects and closes the link; :attr:`link` is what it holds now."""

    def __init__(self, retry_period: float = RETRY_PERIOD):
        self.retry_period = retry_period
        self.link: RobotLink | None = None  # written only by the supervisor's thread; read by anyone
        self.reconnects = 0  # successful reconnects since this supervisor was made
        self._requests: queue.SimpleQueue[Request] = queue.SimpleQueue()
        self._start_guard = threading.Lock()  # held only to start the thread once, or to mark it closed
        self._thread: threading.Thread | None = None
        self._closed = False
        # The thread's own state (nobody else touches it): retry the link while wanted, not before next_try.
        self._wanted = False
        self._next_try = 0.0

    # Requests (any thread) ---------------------------------------------------------------------
    def connect(self, link: RobotLink, timeout: float | None = None) -> LinkState:
        """Hand ``link`` to the supervisor, which closes the current one and opens this; raises
        LinkError. ``timeout`` [s] for the robot's first telemetry (None: :data:`CONNECT_TIMEOUT`)."""
        return self._ask(Connect(link, CONNECT_TIMEOUT if timeout is None else timeout))

    def disconnect(self) -> None:
        """Close the current link and stop retrying it (a no-op when there is none, or after shutdown)."""
        if self._thread is not None and not self._closed:
            self._ask(Disconnect())

    def close(self) -> None:
        """Service shutdown: close the link, end the thread; later requests are refused (a second close too)."""
        with self._start_guard:
            closed_before, self._closed = self._closed, True
            thread = self._thread
        if thread is None or closed_before:
            return
        request = Shutdown()
        self._requests.put(request)
        self._wait(request)
        thread.join(ANSWER_TIMEOUT)

    def lost(self, link: RobotLink, reason: str) -> None:
        """The link's ``on_lost`` callback: a request on the queue, nothing more (the reader thread returns)."""
        self._requests.put(Lost(link, reason))

    def _ask(self, request: Request):
        with self._start_guard:
            if self._closed:
                raise LinkError("the robot service is shutting down")
            if self._thread is None:
                self._thread = threading.Thread(target=self._serve, name="robot-link-supervisor", daemon=True)
                self._thread.start()
        self._requests.put(request)
        return self._wait(request)

    @staticmethod
    def _wait(request: Request):
        try:
            return request.answer.result(ANSWER_TIMEOUT)
        except concurrent.futures.TimeoutError:
            raise LinkError(f"the link's supervisor did not answer within {ANSWER_TIMEOUT:g} s") from None

    # The supervisor's thread -----------------------------------------------------------------
    def _serve(self) -> None:
        while True:
            try:
                request = self._requests.get(timeout=self._until_retry())
            except queue.Empty:
                request = None
            if isinstance(request, Shutdown):
                try:
                    self._close_link()
                except Exception:  # a bug: say so, and end all the same
                    log.exception("the robot link's supervisor failed to close the link at shutdown")
                request.answer.set_result(None)
                return
            try:
                self._handle(request)
            except Exception as error:  # a bug: say so, answer the caller, and keep owning the link
                log.exception("the robot link's supervisor failed on %r", request)
                answer = getattr(request, "answer", None)
                if answer is not None and not answer.done():
                    answer.set_exception(LinkError(f"the link's supervisor failed: {error!r}"))

    def _handle(self, request: Request | None) -> None:
        if isinstance(request, Connect):
            self._connect(request)
        elif isinstance(request, Disconnect):
            self._close_link()
            request.answer.set_result(None)
        elif isinstance(request, Lost) and request.link is self.link:
            log.info("robot link lost (%s); reconnecting every %g s", request.reason, self.retry_period)
        # Whether to retry is decided from the link's state, not from a Lost: one from a link given up
        # since, or queued before a reconnect that worked, changes nothing.
        if self._should_retry() and time.monotonic() >= self._next_try:
            self._retry()

    def _connect(self, request: Connect) -> None:
        """Open ``request.link`` in place of the current link. A connect that fails leaves the
        current link as it was: on another port it is closed only once the new one answers; on the
        same port (one reader per port) it gives way first and, if the new one fails, is reopened
        at once by the retry that follows, as a lost link would be."""
        old, wanted = self.link, self._wanted
        shares_port = old is not None and same_port(old.url, request.link.url)
        if shares_port:
            self._close_link()
        request.link.on_lost.append(functools.partial(self.lost, request.link))
        try:
            state = request.link.connect(request.timeout)
        except LinkError as error:
            if shares_port and wanted:
                self.link, self._wanted, self._next_try = old, True, 0.0
            request.answer.set_exception(error)
            return
        if not shares_port:
            self._close_link()
        self.link, self._wanted, self._next_try = request.link, True, 0.0
        request.answer.set_result(state)

    def _should_retry(self) -> bool:
        return self._wanted and self.link is not None and self.link.state == LinkState.DISCONNECTED

    def _until_retry(self) -> float | None:
        """How long to wait for a request: until the next reconnect attempt, or for ever."""
        return max(0.0, self._next_try - time.monotonic()) if self._should_retry() else None

    def _retry(self) -> None:
        link = self.link
        self._next_try = time.monotonic() + self.retry_period
        try:
            link.reconnect(timeout=self.retry_period)
        except LinkError as error:
            log.debug("reconnect to %s failed: %s", link.url, error)
            return
        self.reconnects += 1
        log.info("robot link to %s is back (%s)", link.url, link.state.value)
        _make_safe(link, "the link came back")  # a run the loss ended: nothing may still move

    def _close_link(self) -> None:
        link, self._wanted = self.link, False
        if link is not None:
            if link.state != LinkState.DISCONNECTED:
                _make_safe(link, "closing the link")  # disconnect, another connect, shutdown
            link.close()
            self.link = None


def same_port(url: str, other: str) -> bool:
    """Whether two link URLs open the same port (a device's symlinks, such as /dev/serial/by-id/…,
    resolved): two links on one port would each read part of the other's frames."""
    if "://" in url or "://" in other:
        return url == other
    return os.path.realpath(url) == os.path.realpath(other)


def _make_safe(link: RobotLink, why: str) -> None:
    """DISARM, confirmed by telemetry (:meth:`RobotLink.make_safe`). Unconfirmed, the link's
    heartbeats end with it, and the robot's own watchdog disarms it within its timeout."""
    try:
        log.info("%s: robot confirmed %s", why, link.make_safe().value)
    except LinkError as error:
        log.info("%s: DISARM not confirmed (%s); the robot's watchdog disarms it", why, error)
