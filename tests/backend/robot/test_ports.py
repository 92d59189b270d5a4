"""Which ports a link may open (backend/robot/ports.py): serial devices and ptys as labs name them,
pyserial's URLs, and never a regular file or another kind of device."""

import os
import re

import pytest

from backend.robot.ports import check_port


@pytest.fixture
def pty_path():
    master, slave = os.openpty()
    yield os.ttyname(slave)
    os.close(slave)
    os.close(master)


@pytest.mark.parametrize("url", ["socket://127.0.0.1:9750", "rfc2217://lab-serial:4001", "loop://", "COM3"])
def test_pyserial_urls_are_accepted(url):
    assert check_port(url) == url


def test_a_pty_and_a_symlink_to_it_are_accepted(pty_path, tmp_path):
    by_id = tmp_path / "usb-Digi_XBee-if00-port0"  # as /dev/serial/by-id/ names one
    by_id.symlink_to(pty_path)
    assert check_port(pty_path) == pty_path
    assert check_port(str(by_id)) == str(by_id)


def test_a_regular_file_is_refused_by_name(tmp_path):
    path = tmp_path / "ttyUSB0"
    path.write_bytes(b"")
    with pytest.raises(ValueError, match=f"^{re.escape(str(path))} is not a character device$"):
        check_port(str(path))
    link = tmp_path / "link"
    link.symlink_to(path)
    with pytest.raises(ValueError, match="not a character device"):
        check_port(str(link))


def test_a_missing_path_is_refused_by_name(tmp_path):
    missing = str(tmp_path / "ttyUSB97")  # a path of this test's own: a machine may have /dev/ttyUSB97
    with pytest.raises(ValueError, match=f"^{re.escape(missing)} does not exist$"):
        check_port(missing)


def test_a_character_device_that_is_not_a_serial_line_is_refused():
    with pytest.raises(ValueError, match="not a serial port or a pty"):
        check_port("/dev/null")


@pytest.mark.parametrize("url", ["http://robot", "socket://a b:1", "socket://host", "ttyUSB0", "loop://?x", ""])
def test_other_urls_are_refused(url):
    with pytest.raises(ValueError):
        check_port(url)
