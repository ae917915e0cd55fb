"""The live viewer's server: it dies with robodyn, and answers loopback pages only."""

from __future__ import annotations

import http.client
import re
import signal
import socket
import subprocess
import sys
import time

import pytest

from robodyn.viz.live import LiveViewer
from tests.conftest import ROOT

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals and ports as on Linux")


def _port_open(port: int) -> bool:
    with socket.socket() as probe:
        probe.settimeout(1)
        return probe.connect_ex(("127.0.0.1", port)) == 0


def _wait_closed(port: int, seconds: float = 10.0) -> bool:
    deadline = time.monotonic() + seconds
    while _port_open(port) and time.monotonic() < deadline:
        time.sleep(0.1)
    return not _port_open(port)


def _start_view():
    process = subprocess.Popen(
        [sys.executable, "-m", "robodyn.cli.app", "view", "rp_arm", "--seconds", "60"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    line = process.stdout.readline()
    port = int(re.search(r"http://127\.0\.0\.1:(\d+)/", line).group(1))
    assert _port_open(port)
    return process, port


@pytest.mark.parametrize("stop", [signal.SIGKILL, signal.SIGHUP])
def test_server_does_not_outlive_robodyn(stop):
    process, port = _start_view()
    try:
        process.send_signal(stop)
        status = process.wait(timeout=20)
        assert status == (-signal.SIGKILL if stop == signal.SIGKILL else 0)
        assert _wait_closed(port), f"the meshcat server outlived robodyn after {stop.name}"
    finally:
        if process.poll() is None:
            process.kill()


def _get(port: int, host: str, origin: str | None = None, websocket: bool = False) -> int:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    headers = {"Host": host}
    if origin is not None:
        headers["Origin"] = origin
    if websocket:
        headers |= {"Upgrade": "websocket", "Connection": "Upgrade", "Sec-WebSocket-Version": "13",
                    "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ=="}  # fmt: skip
    connection.request("GET", "/" if websocket else "/static/", headers=headers)
    status = connection.getresponse().status
    connection.close()
    return status


def test_requests_from_other_origins_are_refused():
    previous = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGHUP)
    stdout = sys.stdout
    with LiveViewer() as viewer:
        assert sys.stdout is stdout
        port = int(re.search(r":(\d+)/", viewer.url).group(1))
        good = f"127.0.0.1:{port}"
        assert _get(port, good) == 200
        assert _get(port, f"localhost:{port}", origin=f"http://localhost:{port}") == 200
        assert _get(port, f"evil.example:{port}") == 403  # DNS rebinding: a foreign name for 127.0.0.1
        assert _get(port, good, origin=f"http://evil.example:{port}") == 403
        assert _get(port, good, websocket=True) == 101
        assert _get(port, good, origin=f"http://{good}", websocket=True) == 101
        assert _get(port, f"evil.example:{port}", origin=f"http://evil.example:{port}", websocket=True) == 403
        assert _get(port, good, origin=f"http://evil.example:{port}", websocket=True) == 403
        assert _get(port, good, origin=f"http://127.0.0.1:{port + 1}", websocket=True) == 403
    assert (signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGHUP)) == previous
    assert _wait_closed(port)


def test_a_loopback_websocket_gets_the_scene():
    import asyncio

    import numpy as np
    import tornado.httpclient
    import tornado.websocket

    import robodyn

    robot = robodyn.load("rp_arm")
    with LiveViewer() as viewer:
        viewer.show(robot, target=np.array([0.5, 0.5]))
        port = int(re.search(r":(\d+)/", viewer.url).group(1))

        async def first_messages(origin: str) -> list[bytes]:
            request = tornado.httpclient.HTTPRequest(f"ws://127.0.0.1:{port}/", headers={"Origin": origin})
            connection = await tornado.websocket.websocket_connect(request)
            messages = [await asyncio.wait_for(connection.read_message(), 5) for _ in range(3)]
            connection.close()
            return messages

        messages = asyncio.run(first_messages(f"http://127.0.0.1:{port}"))
        assert all(isinstance(m, bytes) and len(m) > 10 for m in messages)
        with pytest.raises(tornado.httpclient.HTTPClientError, match="403"):
            asyncio.run(first_messages(f"http://evil.example:{port}"))
