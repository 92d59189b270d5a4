"""The robot service's one tracker: opened from a connect's request, replaced only when the new one
is open, given back when a connect fails.

A connect opens its tracker beside the current one; if its port is taken, the current one gives way
(it may hold that very port) and, should the new one or the link then fail, is opened again from
the request it was made with — a connect that fails leaves the working tracker as it was. A port
that another program holds is a 409 naming it; an address this machine cannot bind, a 422 naming
the field. Only the robot service's connect and disconnect change the slot, under the service's
lock; anyone reads :attr:`TrackerSlot.tracker`.
"""

from __future__ import annotations

import errno
import logging

from backend.robot.natnet import parse_version
from backend.robot.natnet_source import NatNetPoseSource
from backend.robot.tracker import Calibration, UdpPoseSource
from backend.schemas import RobotConnect
from sim_core.model.errors import ParameterError

log = logging.getLogger("parkourlab.robot")

PoseSource = UdpPoseSource | NatNetPoseSource


class TrackerPortInUse(RuntimeError):
    """The tracker's port is held by another program (a 409)."""


class TrackerSlot:
    """The tracker the service holds now (:attr:`tracker`, None when disconnected) and its request."""

    def __init__(self) -> None:
        self.tracker: PoseSource | None = None
        self._request: RobotConnect | None = None

    def open_beside(self, body: RobotConnect) -> PoseSource:
        """The tracker ``body`` asks for, not yet in the slot (:meth:`take` or :meth:`give_up` it).
        If its port is taken, the current tracker gives way first."""
        try:
            return open_tracker(body)
        except OSError as error:
            if error.errno != errno.EADDRINUSE or self.tracker is None:
                raise tracker_error(body, error) from None
        self.tracker.close()
        self.tracker = None
        try:
            return open_tracker(body)
        except OSError as error:
            self._reopen()
            raise tracker_error(body, error) from None

    def take(self, tracker: PoseSource, body: RobotConnect) -> None:
        """The new tracker is the service's: the old one (if it did not give way) is closed."""
        if self.tracker is not None:
            self.tracker.close()
        self.tracker, self._request = tracker, body

    def give_up(self, tracker: PoseSource) -> None:
        """The connect failed: close its tracker, and reopen the working one if it gave way."""
        tracker.close()
        if self.tracker is None:
            self._reopen()

    def close(self) -> None:
        if self.tracker is not None:
            self.tracker.close()
        self.tracker, self._request = None, None

    def _reopen(self) -> None:
        if self._request is None:
            return
        try:
            self.tracker = open_tracker(self._request)
        except OSError as error:
            where = f"{self._request.tracker_host}:{self._request.tracker_port}"
            log.error("could not reopen the tracker at %s: %s", where, error)
            self._request = None


def open_tracker(body: RobotConnect) -> PoseSource:
    """The pose source ``body`` asks for: PKT1 datagrams, or the NatNet stream's rigid body, with
    its camera calibration. Raises OSError if its socket cannot be bound."""
    calibration = Calibration(tuple(body.calibration_origin), body.calibration_angle, body.calibration_scale)
    if body.tracker_protocol == "pkt1":
        return UdpPoseSource(body.tracker_host, body.tracker_port, calibration=calibration)
    return NatNetPoseSource(
        body.natnet_rigid_body_id,
        interface=body.tracker_host,
        port=body.tracker_port,
        multicast_group=body.natnet_multicast_group,
        server=(body.natnet_server_host, body.natnet_command_port),
        version=None if body.natnet_version == "auto" else parse_version(body.natnet_version),
        calibration=calibration,
    )


def tracker_error(body: RobotConnect, error: OSError) -> Exception:
    """A tracker socket that could not be bound, in the operator's terms."""
    where = f"{body.tracker_host}:{body.tracker_port}"
    if error.errno == errno.EADDRINUSE:
        return TrackerPortInUse(f"tracker_port {body.tracker_port}: {where} is in use by another program")
    if error.errno in (errno.EACCES, errno.EPERM):
        return ParameterError("tracker_port", f"this service may not bind {where} ({error.strerror})")
    return ParameterError("tracker_host", f"cannot listen on {where}: {error.strerror or error}")
