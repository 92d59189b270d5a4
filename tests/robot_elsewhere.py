"""A virtual robot in a process of its own, for tests that stall this interpreter.

A test that holds this process' GIL (to stand for a busy service) would stall a virtual robot
running on its threads too, and the robot would read the PC's frames late instead of missing them.
:class:`RobotElsewhere` runs the radio-only :class:`~backend.robot.virtual.VirtualRobot` in a
spawned process, with the watchdog the test chooses, and answers what its firmware reports now and
when each of the PC's messages arrived (``scripts/bench_link_hold.py`` measures the gaps with it);
:func:`hold_the_gil` stalls this interpreter as a compiled kernel does.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import multiprocessing
import time
from dataclasses import dataclass

from backend.robot.messages import RobotState

START_TIMEOUT = 60.0  # [s] a cold interpreter importing the robot on a loaded machine


@dataclass(frozen=True)
class FirmwareNow:
    state: RobotState
    faults: int


def _serve(connection, heartbeat_timeout: float) -> None:
    from backend.robot.firmware import Firmware
    from backend.robot.virtual import VirtualRobot

    robot = VirtualRobot(firmware=Firmware.boot(heartbeat_timeout=heartbeat_timeout))
    arrivals = []  # (monotonic time, kind) of each command the robot's firmware received
    receive = robot.firmware.receive

    def noted(message, now: float):
        arrivals.append((time.monotonic(), getattr(getattr(message, "kind", None), "name", type(message).__name__)))
        return receive(message, now)

    robot.firmware.receive = noted
    robot.start()
    connection.send(robot.url)
    try:
        while (question := connection.recv()) in ("firmware", "arrivals"):
            with robot.lock:
                if question == "firmware":
                    connection.send((int(robot.firmware.state), int(robot.firmware.faults)))
                else:
                    connection.send(list(arrivals))
    except EOFError:
        pass
    finally:
        robot.stop()


class RobotElsewhere:
    """``with RobotElsewhere(heartbeat_timeout=0.35) as robot:`` connect to ``robot.url``."""

    def __init__(self, heartbeat_timeout: float):
        context = multiprocessing.get_context("spawn")
        self._connection, child = context.Pipe()
        self._process = context.Process(target=_serve, args=(child, heartbeat_timeout), daemon=True)
        self.url = ""

    def __enter__(self) -> RobotElsewhere:
        self._process.start()
        if not self._connection.poll(START_TIMEOUT):
            self._process.kill()
            raise RuntimeError(f"the virtual robot's process did not start within {START_TIMEOUT:g} s")
        self.url = self._connection.recv()
        return self

    def firmware(self) -> FirmwareNow:
        self._connection.send("firmware")
        state, faults = self._connection.recv()
        return FirmwareNow(RobotState(state), faults)

    def arrivals(self) -> list[tuple[float, str]]:
        """Every message from the PC the robot received so far: (its arrival on the machine's
        monotonic clock, which every process shares; its kind: HEARTBEAT, ARM, ..., SetLeg)."""
        self._connection.send("arrivals")
        return self._connection.recv()

    def __exit__(self, *_exc) -> None:
        self._connection.send("stop")
        self._process.join(10)
        if self._process.is_alive():
            self._process.kill()


def hold_the_gil(seconds: float) -> float:
    """Hold this interpreter's GIL for ``seconds`` (at least): libc's ``usleep`` called through
    ``ctypes.PyDLL``, which keeps the GIL for the call, as a compiled kernel does. The seconds held."""
    libc = ctypes.PyDLL(ctypes.util.find_library("c"))
    started = time.perf_counter()
    libc.usleep(int(seconds * 1e6))
    return time.perf_counter() - started
