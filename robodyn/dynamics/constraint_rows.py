"""The rows of bound constraints at a state from one Pinocchio kinematics pass.

A copy of the robot's model carries one frame at each end of the constraints that sits on a
link (its origin at the end's point, its axes the end's), so that one pass
(``forwardKinematics`` with ``v̇ = 0``, ``computeJointJacobians``) and three frame calls an
end give each end's world placement, ``LOCAL_WORLD_ALIGNED`` Jacobian ``(J_v; J_ω)`` and
classical acceleration ``(J̇_v v; J̇_ω v)`` at its own point; the rows are then whole-array
products (:class:`robodyn.constraints.algebra.Layout`). Mimic joints are the model's own,
so the frame Jacobians include them.

Inner loops (a simulation asks for the same state several times a step: the projection's
checks, the next step's first stage) get the last state's rows again without recomputing
them (:meth:`EndFrames.rows`, per thread); those arrays are shared and read-only.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from robodyn.constraints.algebra import Bound, Layout

if TYPE_CHECKING:
    from robodyn.dynamics.robot import Robot

Rows = tuple[np.ndarray, np.ndarray, np.ndarray]


class EndFrames:
    """Bound constraints on one robot, ready for their rows at any state.

    Attributes:
        layout: The rows' matrices (:class:`~robodyn.constraints.algebra.Layout`).
        model: The robot's model with a frame at each end on a link (:attr:`frames`, in
            the order of ``layout.linked``).
    """

    def __init__(self, robot: Robot, bounds: tuple[Bound, ...]) -> None:
        self.layout = Layout(bounds)
        self.model = pin.Model(robot.model)
        ends = [end for bound in bounds for end in (bound.first, bound.second)]
        self.frames: list[int] = []
        for number in self.layout.linked:
            end, index = ends[number], robot.handle.frames[str(ends[number].link)]
            link = robot.model.frames[index]
            placement = link.placement * pin.SE3(end.rotation, end.position)
            self.frames.append(
                self.model.addFrame(pin.Frame(f"end{number}", link.parentJoint, index, placement, pin.FrameType.OP_FRAME), False)
            )
        self.zeros = np.zeros(robot.nv)
        self._local = threading.local()

    def _thread(self) -> Any:
        """This thread's data of :attr:`model`, its buffers of the ends' kinematics and its last results."""
        local = self._local
        if not hasattr(local, "data"):
            count, nv = len(self.frames), len(self.zeros)
            local.data, local.memo = self.model.createData(), {}
            local.ends = np.empty((count, 3)), np.empty((count, 6, nv)), np.empty((count, 6))
        return local

    def compute(self, q: np.ndarray, v: np.ndarray) -> Rows:
        """``Φ`` (m,), ``J`` (m, nv), ``J̇ v`` (m,) at one checked state.

        Args:
            q: Configuration, float64, shape (nq,).
            v: Velocity, float64, shape (nv,).
        """
        if not self.frames:
            return np.zeros(0), np.zeros((0, len(self.zeros))), np.zeros(0)
        local, world = self._thread(), pin.LOCAL_WORLD_ALIGNED
        model, data, (positions, jacobians, drifts) = self.model, local.data, local.ends
        pin.forwardKinematics(model, data, q, v, self.zeros)
        pin.computeJointJacobians(model, data)  # from the placements just computed
        rotations = []
        for index, frame in enumerate(self.frames):
            placement = pin.updateFramePlacement(model, data, frame)
            positions[index] = placement.translation
            if self.layout.welds:
                rotations.append(placement.rotation)
            jacobians[index] = pin.getFrameJacobian(model, data, frame, world).reshape(6, -1)  # eigenpy: (6,) at nv = 1
            drifts[index] = pin.getFrameClassicalAcceleration(model, data, frame, world).vector
        return self.layout.assemble(positions, rotations, jacobians, drifts)  # new arrays: the buffers stay here

    def rows(self, q: np.ndarray, v: np.ndarray) -> Rows:
        """:meth:`compute`, or the same state's rows again (read-only, shared): see the module docstring.

        Args:
            q: Configuration, float64, shape (nq,).
            v: Velocity, float64, shape (nv,).
        """
        return self.remember("rows", (q, v), lambda: self.compute(q, v))

    def remember(self, what: str, state: tuple[np.ndarray, ...], compute: Callable[[], tuple[np.ndarray, ...]]) -> Any:
        """``compute()``, or its arrays of the last call with the same ``what`` and equal
        ``state`` arrays in this thread (read-only: they are shared).

        Args:
            what: The name of the result (one memo a name).
            state: The arrays the result depends on.
            compute: Computes the result's arrays when the state is new.
        """
        memo, key = self._thread().memo, b"".join(array.tobytes() for array in state)
        last = memo.get(what)
        if last is not None and last[0] == key:
            return last[1]
        result = compute()
        for array in result:
            array.flags.writeable = False
        memo[what] = (key, result)
        return result


__all__ = ["EndFrames", "Rows"]
