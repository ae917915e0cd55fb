"""Pinocchio on several threads: one ``Data`` a thread, and batches of states on native threads.

A :class:`PerThreadData` gives each thread its own Pinocchio ``Data`` (scratch memory that
every algorithm overwrites), so one model can be used from several threads at once.
A :class:`ParallelRunner` runs Pinocchio's ``rneaInParallel`` / ``abaInParallel``: it keeps
the ``ModelPool`` those functions need (built on first use) and the number of threads.
States come one a row (robodyn's shape rule); Pinocchio wants one a column, so the runner
passes transposed views and transposes the result back.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

import numpy as np
import pinocchio as pin

from robodyn.exceptions import InputError


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity), at least 1."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def check_threads(threads: int | None) -> int:
    """A thread count: ``None`` means every available core; else a whole number ≥ 1.

    Args:
        threads: The thread count asked for, or ``None``.

    Raises:
        InputError: For anything else.
    """
    if threads is None:
        return available_cores()
    if isinstance(threads, bool) or not isinstance(threads, int | np.integer) or threads < 1:
        raise InputError("threads", "a whole number ≥ 1 (or None for every core)", repr(threads))
    return int(threads)


class PerThreadData:
    """One Pinocchio ``Data`` for ``model`` per thread, created on first use in that thread."""

    def __init__(self, model: pin.Model) -> None:
        self._model = model
        self._local = threading.local()
        #: This thread's data is ``local.data`` once :meth:`get` made it (an
        #: ``AttributeError`` before): the hot path reads it without a call.
        self.local = self._local

    def get(self) -> pin.Data:
        """This thread's data."""
        try:
            return self._local.data
        except AttributeError:
            data = self._local.data = self._model.createData()
            return data


class ParallelRunner:
    """Runs Pinocchio's parallel algorithms on stacks of states.

    Args:
        model: The Pinocchio model.
        threads: Native threads; ``None`` for every available core.
    """

    def __init__(self, model: pin.Model, *, threads: int | None = None) -> None:
        self._model = model
        self.threads = check_threads(threads)
        self._pool: pin.ModelPool | None = None
        self._lock = threading.Lock()

    def _model_pool(self) -> pin.ModelPool:
        with self._lock:
            if self._pool is None:
                self._pool = pin.ModelPool(self._model, self.threads)
            return self._pool

    def run(self, algorithm: Callable, q: np.ndarray, v: np.ndarray, third: np.ndarray) -> np.ndarray:
        """``algorithm(threads, pool, q, v, third)`` on stacks of shape (N, ·); result (N, nv).

        A pool's data is shared by its calls, so concurrent batches of one runner are
        serialised.

        Args:
            algorithm: A Pinocchio parallel algorithm (e.g. ``rneaInParallel``), called with column-major stacks.
            q: Configurations, shape (N, nq).
            v: Velocities, shape (N, nv).
            third: The algorithm's third argument (accelerations or torques), shape (N, nv).
        """
        nv = self._model.nv
        if q.shape[0] == 0:
            return np.zeros((0, nv))
        columns = [np.ascontiguousarray(array).T for array in (q, v, third)]
        pool = self._model_pool()
        with self._lock:
            result = algorithm(self.threads, pool, *columns)
        return np.asarray(result).reshape(nv, q.shape[0]).T.copy()
