"""Which ports a robot link may open: serial devices as labs name them, and pyserial's network URLs.

A USB radio appears as ``/dev/ttyUSB0`` or ``/dev/ttyACM0`` (Linux), ``/dev/cu.usbserial-…``
(macOS), or through the stable symlinks ``/dev/serial/by-id/…`` and ``/dev/serial/by-path/…``;
a test rig or ``socat`` gives a pty (``/dev/pts/N``); a serial server gives ``rfc2217://``; the
virtual robot ``socket://``. The check follows symlinks and looks at what the path is, so a
regular file is never opened, and neither is a character device that is not a serial line —
opening ``/dev/watchdog`` arms a hardware watchdog. Once open, :func:`no_delay` sets up a
network transport for small frames, and :func:`write_within` writes a frame with a deadline.
"""

from __future__ import annotations

import contextlib
import os
import re
import select
import socket
import stat
import time

import serial

# pyserial's URLs a link may open (no options), and Windows' COM ports.
SERIAL_URL = re.compile(r"^((socket|rfc2217)://[\w.-]+:[0-9]{1,5}|loop://|COM[0-9]{1,3})$")
SERIAL_DEVICE = re.compile(r"^/dev/(tty[\w.-]*|cu\.[\w.-]+|pts/[0-9]+|rfcomm[0-9]+)$")


def check_port(url: str) -> str:
    """``url`` if a link may open it, else ValueError naming it: a pyserial socket, RFC 2217 or loop
    URL, a Windows ``COMn``, or an existing character device (or a symlink to one, as
    ``/dev/serial/by-id/…``) that is a serial port or a pty. A regular file, a block device or
    another kind of character device (``/dev/watchdog``, ``/dev/mem``) is never opened."""
    if SERIAL_URL.match(url):
        return url
    if not url.startswith("/"):
        raise ValueError(f"{url!r} is not a device path, socket://host:port, rfc2217://host:port or loop://")
    try:
        mode = os.stat(url).st_mode  # follows symlinks
    except (OSError, ValueError):  # ValueError: a NUL in the path
        raise ValueError(f"{url} does not exist") from None
    if not stat.S_ISCHR(mode):
        raise ValueError(f"{url} is not a character device")
    target = os.path.realpath(url)
    if not SERIAL_DEVICE.match(target):
        raise ValueError(f"{url} ({target}) is not a serial port or a pty")
    return url


def no_delay(port) -> None:
    """TCP_NODELAY on a socket:// or rfc2217:// transport: an e-stop must not wait behind Nagle's
    algorithm for the previous segment's ACK. pyserial keeps the socket in ``_socket``."""
    sock = getattr(port, "_socket", None)
    if isinstance(sock, socket.socket) and sock.family in (socket.AF_INET, socket.AF_INET6):
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)


def write_within(port, data: bytes, deadline: float) -> None:
    """All of ``data`` on ``port`` by ``deadline`` (``time.monotonic()``), or
    ``serial.SerialTimeoutException`` if the line did not take it all by then.

    pyserial's own bounded write checks its timeout after the bytes have gone, so a thread kept
    waiting (the OS, the GIL) after a complete write is told the line is jammed — and the caller
    reports a command as failed that the robot received. Here a write is late only if bytes are
    left over: on a serial device or pty (pyserial keeps its fd non-blocking) and on a
    ``socket://`` transport (a non-blocking socket) the bytes are written directly, waiting for
    room until the deadline; other transports (``rfc2217://``, ``loop://``) keep pyserial's write.
    """
    fd, sock = getattr(port, "fd", None), getattr(port, "_socket", None)
    if isinstance(fd, int) and not os.get_blocking(fd):
        send, waitable = (lambda chunk: os.write(fd, chunk)), fd
    elif isinstance(sock, socket.socket) and not sock.getblocking():
        send, waitable = sock.send, sock
    else:
        port.write_timeout = max(0.001, deadline - time.monotonic())
        port.write(data)
        return
    left = memoryview(data)
    while left:
        with contextlib.suppress(BlockingIOError, InterruptedError):
            left = left[send(left) :]
        if left:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise serial.SerialTimeoutException("Write timeout")
            select.select([], [waitable], [], remaining)
