"""``parkour serve`` as a person starts it: what it prints, and the sign-in link working."""

import subprocess
import sys
import time

import httpx

from tests.helpers import SERVICE_START_TIMEOUT, free_port


def test_serve_prints_a_sign_in_link_that_carries_the_token_in_its_fragment(tmp_path):
    port = free_port()
    command = [sys.executable, "-m", "cli", "serve", "--data-dir", str(tmp_path), "--port", str(port), "--no-view"]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        lines, deadline = [], time.monotonic() + SERVICE_START_TIMEOUT
        while not any("sign in" in line for line in lines):
            assert time.monotonic() < deadline and process.poll() is None, lines
            lines.append(process.stderr.readline())
        link = next(line for line in lines if "sign in" in line).split()[-1]
        token = (tmp_path / "api_token").read_text().strip()
        assert link == f"http://127.0.0.1:{port}/panel/#token={token}", "the token in the fragment: never sent"
        panel, _, _ = link.partition("#")
        while True:  # the panel the link opens, and the token it carries accepted
            try:
                assert httpx.get(panel).status_code == 200
                break
            except httpx.ConnectError:
                assert time.monotonic() < deadline
                time.sleep(0.2)
        assert httpx.get(f"http://127.0.0.1:{port}/api/v1/auth", headers={"Authorization": f"Bearer {token}"}).json()
    finally:
        process.terminate()
        process.wait(30)
