"""Meshcat's server for robodyn's live viewer (``python -m robodyn.viz.server ZMQ_URL PORT PARENT_PID``).

Differences from meshcat's own server:

- it listens on 127.0.0.1 only;
- every HTTP and websocket request must carry ``Host: 127.0.0.1:PORT`` (or
  ``localhost:PORT``) and, when it has one, an ``Origin`` of that address: a page of
  another site that rebinds its DNS name to 127.0.0.1 gets 403 and no scene;
- it ends with its parent: ``PR_SET_PDEATHSIG`` (Linux) sends it SIGTERM when the parent
  dies, and a check each half second stops it once the parent is gone (everywhere).

Prints ``web_url=...`` once listening.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys

import tornado.ioloop
import tornado.web
from meshcat.servers.zmqserver import VIEWER_HTML, VIEWER_ROOT, StaticFileHandlerNoCache, WebSocketHandler, ZMQWebSocketBridge

PR_SET_PDEATHSIG = 1


def bind_to_parent(parent: int) -> None:
    """Die with the parent process: SIGTERM on its death (Linux); exit if it is already gone.

    Args:
        parent: The parent's process id.
    """
    if sys.platform.startswith("linux"):
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
    if os.getppid() != parent:  # the parent died before the prctl
        sys.exit(0)


class _Loopback:
    """Refuse a request whose Host or Origin names anything but this server's loopback address."""

    allowed_hosts: frozenset[str] = frozenset()

    def prepare(self):
        host = self.request.headers.get("Host", "")
        origin = self.request.headers.get("Origin")
        if host not in self.allowed_hosts or (origin is not None and origin not in self.allowed_origins):
            raise tornado.web.HTTPError(403)
        return super().prepare()

    @property
    def allowed_origins(self) -> set[str]:
        return {f"http://{host}" for host in self.allowed_hosts}

    def check_origin(self, origin: str) -> bool:  # websocket handshakes
        return origin in self.allowed_origins


class LoopbackBridge(ZMQWebSocketBridge):
    """Meshcat's bridge on 127.0.0.1 whose handlers accept loopback Host/Origin only."""

    def __init__(self, *, zmq_url: str, port: int):
        hosts = frozenset({f"127.0.0.1:{port}", f"localhost:{port}"})
        self._static = type("LoopbackStatic", (_Loopback, StaticFileHandlerNoCache), {"allowed_hosts": hosts})
        self._websocket = type("LoopbackWebSocket", (_Loopback, WebSocketHandler), {"allowed_hosts": hosts})
        super().__init__(zmq_url=zmq_url, host="127.0.0.1", port=port)

    def make_app(self):
        app = tornado.web.Application(
            [
                (r"/static/(.*)", self._static, {"path": VIEWER_ROOT, "default_filename": VIEWER_HTML}),
                (r"/", self._websocket, {"bridge": self}),
            ]
        )
        listen = app.listen
        app.listen = lambda port, **kwargs: listen(port, address="127.0.0.1", **kwargs)
        return app


def main() -> None:
    """Start the bridge on the given ZMQ URL and web port, and serve while the parent lives."""
    zmq_url, port, parent = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    bind_to_parent(parent)
    bridge = LoopbackBridge(zmq_url=zmq_url, port=port)

    def parent_gone() -> None:
        if os.getppid() != parent:
            bridge.ioloop.stop()

    tornado.ioloop.PeriodicCallback(parent_gone, 500).start()
    print(f"web_url={bridge.web_url}", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        bridge.run()


if __name__ == "__main__":
    main()
