"""Meshcat's server, bound to 127.0.0.1 (run as ``python -m robodyn.viz.server ZMQ_URL PORT``).

Out of the box meshcat's web server listens on every interface; robodyn's live viewer
runs this instead, so the viewer is reachable from this machine only. Prints
``web_url=...`` once listening.
"""

from __future__ import annotations

import contextlib
import sys

from meshcat.servers.zmqserver import ZMQWebSocketBridge


class LocalBridge(ZMQWebSocketBridge):
    """Meshcat's bridge whose web server listens on 127.0.0.1 only."""

    def make_app(self):
        app = super().make_app()
        listen = app.listen
        app.listen = lambda port, **kwargs: listen(port, address="127.0.0.1", **kwargs)
        return app


def main() -> None:
    """Start the bridge on the given ZMQ URL and web port, and serve until terminated."""
    zmq_url, port = sys.argv[1], int(sys.argv[2])
    bridge = LocalBridge(zmq_url=zmq_url, host="127.0.0.1", port=port)
    print(f"web_url={bridge.web_url}", flush=True)
    with contextlib.suppress(KeyboardInterrupt):
        bridge.run()


if __name__ == "__main__":
    main()
