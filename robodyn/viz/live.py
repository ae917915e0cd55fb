"""The live viewer: meshcat's server on 127.0.0.1 for one robodyn session.

The server (:mod:`robodyn.viz.server`) runs as a child process bound to robodyn's life:
it has its own process group, asks Linux for SIGTERM when its parent dies
(``PR_SET_PDEATHSIG``) and, everywhere, stops when its parent is gone. So neither SIGKILL
nor SIGHUP of ``robodyn view`` leaves a server behind. It refuses HTTP and websocket
requests whose ``Host`` or ``Origin`` is not this loopback address and port (DNS
rebinding). Commands go to it over a ZeroMQ socket on 127.0.0.1.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Callable
from types import FrameType
from typing import TYPE_CHECKING, Any

import numpy as np
import umsgpack

from robodyn.dynamics.robot import Robot
from robodyn.exceptions import ViewerError
from robodyn.trajectory import Trajectory

if TYPE_CHECKING:
    import zmq

#: What ``signal.signal`` takes and returns.
_Handler = Callable[[int, FrameType | None], Any] | int | signal.Handlers | None

#: Signals that end a live session normally (the server is stopped, exit status 0).
STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class LiveViewer:
    """Meshcat's server for one session, listening on 127.0.0.1 only.

    Use as a context manager: the server process is stopped on exit, on an exception and
    on SIGTERM/SIGHUP (which become :class:`KeyboardInterrupt`, like Ctrl-C); the previous
    signal handlers are restored on exit.

    Attributes:
        url: The page to open in a browser.
    """

    def __init__(self) -> None:
        self._process: subprocess.Popen | None = None
        self._socket: zmq.Socket | None = None
        self._context: zmq.Context | None = None
        self._previous: dict[int, _Handler] = {}
        self.url = ""

    def __enter__(self) -> LiveViewer:
        import zmq

        web_port, zmq_port = _free_port(), _free_port()
        zmq_url = f"tcp://127.0.0.1:{zmq_port}"
        self._process = process = subprocess.Popen(
            [sys.executable, "-m", "robodyn.viz.server", zmq_url, str(web_port), str(os.getpid())],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            stdin=subprocess.DEVNULL,
            start_new_session=True,  # its own process group: a terminal's signals reach robodyn only
        )
        assert process.stdout is not None  # stdout=PIPE
        line = process.stdout.readline().decode().strip()
        if not line.startswith("web_url="):
            self.close()
            raise ViewerError("the meshcat server did not start.")
        self.url = line.removeprefix("web_url=")
        self._context = context = zmq.Context()
        self._socket = requests = context.socket(zmq.REQ)
        requests.setsockopt(zmq.LINGER, 0)
        requests.connect(zmq_url)
        for number in STOP_SIGNALS:
            self._previous[number] = signal.signal(number, _raise_interrupt)
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def close(self) -> None:
        """Stop the server and restore the signal handlers (idempotent)."""
        for number, handler in self._previous.items():
            signal.signal(number, handler)
        self._previous = {}
        if self._socket is not None and self._context is not None:  # set together
            self._socket.close()
            self._context.term()
            self._socket = self._context = None
        if self._process is not None and self._process.poll() is None:
            self._process.terminate()
            try:
                self._process.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self._process.kill()
                self._process.wait()
        if self._process is not None and self._process.stdout is not None:
            self._process.stdout.close()
        self._process = None

    def send(self, commands: list[dict]) -> None:
        """Send lowered meshcat commands to the viewer.

        Args:
            commands: Meshcat commands, lowered to dicts.
        """
        if self._socket is None:
            raise ViewerError("the live viewer is not running.")
        for command in commands:
            self._socket.send_multipart([command["type"].encode(), command.get("path", "").encode(), umsgpack.packb(command)])
            self._socket.recv()

    def show(self, robot: Robot, trajectory: Trajectory | None = None, *, fps: float = 30.0, target=None, frame=None) -> None:
        """Draw the robot (at its start, :meth:`~robodyn.Robot.default_configuration`, or playing the trajectory) with its
        task: ground grid, ``target`` marker (X,Z or X,Y,Z in [m]) and the frame's path.

        Args:
            robot: The robot drawn.
            trajectory: The motion to play (``None``: the robot at rest).
            fps: Animation frames per second.
            target: The task target, X,Z (planar, Y = 0) or X,Y,Z in [m] (``None``: none).
            frame: The frame whose path is drawn (``None``: ``robot.end_effector``, none when the robot has no
                default).
        """
        from robodyn.viz.recording import motion_commands

        if trajectory is None:
            q = robot.default_configuration()[None]
            zeros = np.zeros((1, robot.nv))
            trajectory = Trajectory(np.zeros(1), q, zeros, zeros, zeros, robot.joint_names, robot.name)
        commands, _duration, _placeholders = motion_commands(robot, trajectory, fps=fps, target=target, frame=frame)
        self.send(commands)


def _raise_interrupt(signum, frame) -> None:
    raise KeyboardInterrupt


def wait(seconds: float | None) -> None:
    """Sleep ``seconds`` (forever when ``None``) until interrupted.

    Args:
        seconds: How long in [s] (``None``: forever).
    """
    deadline = None if seconds is None else time.monotonic() + seconds
    while deadline is None or time.monotonic() < deadline:
        time.sleep(0.2)
