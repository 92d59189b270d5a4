"""Body poses from the camera software's NatNet stream: one rigid body of it, in a background thread.

Axes: the air table's plane is the stream's x–y plane (in Motive, stream with the Z axis up and
the ground plane set on the table), so the rigid body's position ``(x, y, z)`` gives the camera
point ``(x, y)`` and its rotation about z (counter-clockwise seen from +z) the pitch [rad]. The
:class:`backend.robot.tracker.Calibration` then maps the camera point to wall coordinates exactly
as for PKT1 datagrams (the pitch passes unchanged, as for PKT1). ``z`` (the height above the
table) is not used.

Multicast (the camera software's default): the data port (1511) is bound on all interfaces and the
group joined on ``interface`` (IP_ADD_MEMBERSHIP). Unicast: the server streams to whichever
address asked it to, so one socket sends the connect request to the server's command port and
receives the frames there, sending a keep-alive every second. In both modes a connect request
goes to the server each second until it answers; its answer (``NAT_SERVERINFO``) names the
stream's NatNet version, which is used unless a version was configured (the V100 rig's old
software: configure it when its server does not answer). Frames that arrive while the version is
still unknown, or that lack the rigid body or say it is untracked, are counted as ``ignored``. A
malformed packet is counted in ``malformed`` only: the whole frame is decoded (and its pose checked)
before its number reaches :class:`~backend.robot.tracker.TrackerStats`, and the number it leaves out
is not counted ``dropped`` as well.

A ``NAT_SERVERINFO`` is taken only from the configured server's address and command port, and
only while its answer is awaited (after a connect request, before the first answer): any other
(a second answer, a stray one, one from another host or port) is counted in
``server_info_refused`` and changes nothing. An answer naming a version this reader does not know
sets ``error`` and leaves the version unknown, so no frame is decoded on a guess.
"""

from __future__ import annotations

import logging
import math
import select
import socket
import struct
import threading
import time

from backend.robot.natnet import (
    COMMAND_PORT,
    DATA_PORT,
    KNOWN_VERSIONS,
    MULTICAST_GROUP,
    NAT_FRAMEOFDATA,
    NAT_SERVERINFO,
    NatNetError,
    Version,
    connect_request,
    decode_server_info,
    format_version,
    is_known,
    keep_alive,
    message_id,
)
from backend.robot.natnet_frame import decode_frame
from backend.robot.tracker import Calibration, Pose, PoseHistory, TrackerStats, readable

log = logging.getLogger("parkourlab.robot")
REQUEST_EVERY = 1.0  # [s] connect requests until the server answers; a unicast client's keep-alives
RECEIVE_BUFFER = 65536  # a NatNet message has a 16-bit size: one datagram always fits


class NatNetPoseSource(PoseHistory):
    """Poses of rigid body ``rigid_body_id`` from a NatNet server.

    ``multicast_group`` None means unicast: frames arrive on ``interface:port`` (0: any free port),
    where the connect request is sent from. Otherwise ``port`` is the stream's data port and the
    group is joined on ``interface`` (``0.0.0.0``: the system's choice). ``server`` is the NatNet
    server's command address. ``version`` ``(major, minor)`` is the stream's NatNet version, None
    to take the server's word for it.

    For records and the robot's status: ``protocol`` ``"natnet"``, ``version`` the stream's version
    as ``"M.m"`` (None while unknown), ``error`` why no frame can be read (None: nothing wrong known).
    """

    protocol = "natnet"

    def __init__(
        self,
        rigid_body_id: int = 1,
        *,
        interface: str = "0.0.0.0",
        port: int = DATA_PORT,
        multicast_group: str | None = MULTICAST_GROUP,
        server: tuple[str, int] = ("127.0.0.1", COMMAND_PORT),
        version: Version | None = None,
        calibration: Calibration | None = None,
        **kwargs,
    ):
        super().__init__(calibration or Calibration(), **kwargs)
        self.rigid_body_id = rigid_body_id
        self.server = server
        self.configured_version = version
        self.stream_version = version  # the one frames are read with (None: not known yet)
        self.server_info = None  # the server's answer to a connect request, once it came
        self.server_info_refused = 0  # NAT_SERVERINFO messages not taken (see the module docstring)
        self.error: str | None = None
        self._server_ip: str | None = None  # the server's host, resolved when the first request goes
        self.stats = TrackerStats()
        self.multicast_group = multicast_group
        self.command = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            if multicast_group is None:
                self.command.bind((interface, port))
                self.data = self.command
            else:
                self.command.bind((interface, 0))
                self.data = _multicast_socket(multicast_group, interface, port)
        except OSError:
            self.command.close()
            raise
        self.address = self.data.getsockname()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._receive, name="tracker-natnet", daemon=True)
        self._thread.start()

    @property
    def version(self) -> str | None:
        """The stream's NatNet version as ``"M.m"``, None while it is not known."""
        return None if self.stream_version is None else format_version(self.stream_version)

    def waiting(self) -> bool:
        sockets = {self.command, self.data}
        return readable(*sockets)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(2)
        self.command.close()
        if self.data is not self.command:
            self.data.close()

    def _request(self, data: bytes) -> None:
        try:
            if self._server_ip is None:
                self._server_ip = socket.gethostbyname(self.server[0])
            self.command.sendto(data, (self._server_ip, self.server[1]))
        except OSError as error:  # no name or route yet, or the server's port refused an earlier request
            log.debug("NatNet request to %s: %s", self.server, error)

    def _receive(self) -> None:
        sockets = [self.command] if self.data is self.command else [self.command, self.data]
        next_request = 0.0
        while not self._stop.is_set():
            if time.monotonic() >= next_request:
                next_request = time.monotonic() + REQUEST_EVERY
                if self.server_info is None:
                    self._request(connect_request(self.configured_version))
                elif self.multicast_group is None:
                    self._request(keep_alive())
            try:
                ready, _, _ = select.select(sockets, [], [], 0.05)
                for ready_socket in ready:
                    self._handle(*ready_socket.recvfrom(RECEIVE_BUFFER))
            except ConnectionRefusedError:  # an ICMP answer to a request: nothing listens there yet
                continue
            except (OSError, ValueError):  # closed
                return

    def _handle(self, data: bytes, sender: tuple[str, int]) -> None:
        try:
            ident = message_id(data)
            if ident == NAT_SERVERINFO:
                self._learn(data, sender)
            elif ident == NAT_FRAMEOFDATA:
                self._frame(data)
            # Other messages (model definitions, responses, strings) carry no pose.
        except NatNetError as error:
            self.stats.malformed += 1
            log.debug("NatNet packet of %d bytes: %s", len(data), error)

    def _learn(self, data: bytes, sender: tuple[str, int]) -> None:
        awaited = self.server_info is None and self._server_ip is not None  # a connect request went out
        if not awaited or sender[:2] != (self._server_ip, self.server[1]):
            self.server_info_refused += 1
            log.debug("NatNet server info from %s not taken (awaited: %s)", sender, awaited)
            return
        info = decode_server_info(data)
        self.server_info = info
        streamed = info.natnet_version[:2]
        if self.configured_version is not None:
            if streamed != self.configured_version:
                log.warning(
                    "NatNet server %s streams %s; reading it as the configured %s",
                    info.application,
                    format_version(streamed),
                    format_version(self.configured_version),
                )
        elif is_known(streamed):
            self.stream_version = streamed
        else:
            self.error = (
                f"NatNet server {info.application} reports version {format_version(streamed)}; "
                f"this reader knows {KNOWN_VERSIONS}"
            )
            log.warning("%s", self.error)

    def _frame(self, data: bytes) -> None:
        if self.stream_version is None:
            self.stats.ignored += 1
            return
        frame = decode_frame(data, self.stream_version)
        body = frame.rigid_body(self.rigid_body_id)
        if body is not None and not all(math.isfinite(v) for v in (*body.position, *body.orientation)):
            raise NatNetError(f"rigid body {body.id} has a non-finite pose")
        self.stats.frame(frame.number)
        if body is None or not body.tracked:
            self.stats.ignored += 1
            return
        self.add(Pose(frame.timestamp, body.position[0], body.position[1], body.angle_about_z))


def _multicast_socket(group: str, interface: str, port: int) -> socket.socket:
    """A socket on the data ``port`` of every interface, in ``group`` on ``interface``. Several
    programs may listen to one stream (SO_REUSEADDR), as with the camera software's own clients."""
    data = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        data.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        data.bind(("", port))
        membership = struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton(socket.gethostbyname(interface)))
        data.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
    except OSError:
        data.close()
        raise
    return data
