"""What every computation on a Pinocchio model shares: the model, per-thread data, and the input boundary.

:class:`ModelHandle` is the base of :class:`robodyn.Robot`. It owns the one rule by which
robodyn accepts numbers (:meth:`ModelHandle.validate`) and the fast path that tries
Pinocchio directly first (:meth:`ModelHandle._evaluate`).

Thread safety: Pinocchio's ``Data`` is scratch memory that every algorithm overwrites. A
handle keeps one ``Data`` per thread (:attr:`ModelHandle.data`), so one robot may be used
from several threads at once; the model itself is only read.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from robodyn.common.inputs import as_states
from robodyn.exceptions import InputError, NonFiniteResultError

#: Largest accepted deviation of a floating base's quaternion norm from 1.
QUATERNION_TOLERANCE = 1e-6
#: What Pinocchio raises for arguments it refuses (wrong size, type, unsupported joint).
PINOCCHIO_ERRORS = (TypeError, ValueError, RuntimeError, AttributeError)
_isfinite = math.isfinite


class PerThreadData:
    """One Pinocchio ``Data`` for ``model`` per thread, created on first use in that thread."""

    def __init__(self, model: pin.Model) -> None:
        self._model = model
        self._local = threading.local()

    def get(self) -> pin.Data:
        """This thread's data."""
        try:
            return self._local.data
        except AttributeError:
            data = self._local.data = self._model.createData()
            return data


class ModelHandle:
    """A Pinocchio model with per-thread data and robodyn's input checks.

    Attributes:
        model: The Pinocchio model (read only).
        name: Robot name, for messages.
        nq, nv: Sizes of a configuration and of a velocity.
        floating_base: Whether the root is a free-flyer joint (``q[3:7]`` a quaternion).
    """

    def __init__(self, model: pin.Model, *, name: str, floating_base: bool) -> None:
        self.model = model
        self.name = name
        self.floating_base = floating_base
        self.nq: int = model.nq
        self.nv: int = model.nv
        self._data = PerThreadData(model)
        #: What :meth:`_evaluate` computes, by quantity: ``(one state, batch or None)``,
        #: set up once by the subclass (so a call builds no closures).
        self._kernels: dict[str, tuple[Callable[..., np.ndarray], Callable[..., np.ndarray] | None]] = {}

    @property
    def data(self) -> pin.Data:
        """This thread's Pinocchio data for :attr:`model` (created on first use)."""
        return self._data.get()

    # ----------------------------------------------------------------------------------
    # The input boundary
    # ----------------------------------------------------------------------------------
    def validate(self, **named: object) -> tuple[list[np.ndarray], bool]:
        """Check state arguments by name (``q`` has nq entries, the others nv).

        Returns:
            The arguments as float64 arrays, and whether they are a batch (2-D).

        Raises:
            InputError: Naming the argument: wrong type, shape or size, NaN or inf, a
                complex value, or a floating base's quaternion that is not unit.
        """
        arrays, batch = as_states({name: (value, self.nq if name == "q" else self.nv) for name, value in named.items()})
        if self.floating_base and "q" in named:
            norms = np.atleast_1d(np.linalg.norm(arrays[0][..., 3:7], axis=-1))
            worst = int(np.argmax(np.abs(norms - 1.0))) if norms.size else 0
            if norms.size and abs(norms[worst] - 1.0) >= QUATERNION_TOLERANCE:
                raise InputError("q[3:7]", "a unit quaternion (x, y, z, w) for the floating base", f"norm {norms[worst]:.9g}")
        return arrays, batch

    def _accept(self, result: np.ndarray, q: np.ndarray) -> bool:
        """Whether a fast-path result can be returned as it is.

        A NaN or inf anywhere in the inputs makes a result non-finite (detected by one dot
        product; ``q`` is checked too since some algorithms do not propagate it), and a
        floating base needs a unit quaternion. Anything else is re-done through
        :meth:`validate`, which names the offending argument.
        """
        if not (_all_finite(result) and _all_finite(q)):
            return False
        if self.floating_base:
            quaternion = q[3:7]
            return abs(quaternion.dot(quaternion) - 1.0) < QUATERNION_TOLERANCE
        return True

    def _finite(self, result: np.ndarray, what: str) -> np.ndarray:
        """Refuse a non-finite result of finite inputs (an overflow), never return it."""
        if not np.isfinite(result).all():
            raise NonFiniteResultError(self.name, what)
        return result

    def _evaluate(self, what: str, names: tuple[str, ...], *values: np.ndarray) -> np.ndarray:
        """Fast path, then checked path, for the quantity ``what`` of :attr:`_kernels`.

        Its one-state function runs on the raw arguments if Pinocchio takes them and the
        result passes :meth:`_accept`; else the arguments (named ``names``, for messages)
        go through :meth:`validate` and one state goes to the one-state function, a batch
        to the batch function (or to the one-state function row by row when there is none).
        """
        single, batch = self._kernels[what]
        try:
            result = single(*values)
            q = values[0]
            # _accept, written out on the hot path: finite result and q, unit quaternion.
            if (
                (_isfinite(sum(result.tolist())) if result.ndim == 1 else _all_finite(result))
                and _isfinite(sum(q.tolist()))
                and (not self.floating_base or self._accept(result, q))
            ):
                return result
        except PINOCCHIO_ERRORS:
            pass
        arrays, is_batch = self.validate(**dict(zip(names, values, strict=True)))
        if not is_batch:
            return self._finite(single(*arrays), what)
        if batch is not None:
            return self._finite(batch(*arrays), what)
        return self._finite(per_state(single, *arrays), what)


def _all_finite(array: np.ndarray) -> bool:
    """Whether an array holds no NaN or inf, by the cheapest exact test for its size: a NaN
    or inf anywhere makes the sum (a vector) or the sum of squares (a matrix) non-finite; a
    finite sum that overflows only sends the caller to the exact check."""
    if array.ndim == 1:
        return _isfinite(sum(array.tolist()))
    flat = array.ravel()
    return _isfinite(flat.dot(flat))


def per_state(function: Callable[..., np.ndarray], *states: np.ndarray) -> np.ndarray:
    """Apply a one-state function to 1-D states, or to each row of 2-D stacks (stacked)."""
    if states[0].ndim == 1:
        return function(*states)
    results = [function(*row) for row in zip(*states, strict=True)]
    if results:
        return np.stack(results)
    return np.zeros((0, *np.shape(function(*(np.zeros(s.shape[1]) for s in states)))))
