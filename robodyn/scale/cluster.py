"""Where Dask work runs: ``--scheduler ADDRESS`` (an existing ``dask.distributed`` scheduler)
or ``--scheduler local:N`` (a LocalCluster of N worker processes on 127.0.0.1, one thread
each, stopped at the end)."""

from __future__ import annotations

import contextlib
import re
from collections.abc import Iterator

from robodyn.exceptions import InputError, MissingExtraError, SchedulerError

_LOCAL = re.compile(r"^local:(\d+)$")
#: Largest N of ``local:N`` (each worker is a process).
MAX_LOCAL_WORKERS = 64


def check_scheduler(text: str) -> str:
    """``local:N`` (1 ≤ N ≤ 64) or a scheduler address such as ``tcp://10.0.0.5:8786``.

    Args:
        text: The scheduler as given.

    Raises:
        InputError: For anything else.
    """
    match = _LOCAL.match(text)
    if match:
        if not 1 <= int(match.group(1)) <= MAX_LOCAL_WORKERS:
            raise InputError("scheduler", f"local:N with 1 ≤ N ≤ {MAX_LOCAL_WORKERS}", repr(text))
        return text
    if not re.match(r"^(tcp|tls|inproc|ucx|ws|wss)://[^\s]+$|^[\w.\-]+:\d+$", text):
        raise InputError("scheduler", "a scheduler address (tcp://host:port) or local:N", repr(text))
    return text


@contextlib.contextmanager
def connect(scheduler: str, *, timeout: float = 20.0) -> Iterator:
    """A ``dask.distributed.Client`` for ``scheduler`` (see the module docstring).

    Args:
        scheduler: ``local:N`` (a local cluster of N workers) or a scheduler address.
        timeout: How long to wait for the scheduler, in [s].

    Raises:
        RobodynError: If Dask is not installed or the scheduler cannot be reached.
    """
    check_scheduler(scheduler)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise MissingExtraError("dask.distributed", "scale", "a Dask scheduler (scheduler=...)") from None
    match = _LOCAL.match(scheduler)
    if match:
        cluster = LocalCluster(
            n_workers=int(match.group(1)),
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            silence_logs=40,
        )
        with cluster, Client(cluster) as client:
            yield client
        return
    try:
        client = Client(scheduler, timeout=timeout)
    except (OSError, TimeoutError) as error:
        raise SchedulerError(scheduler, f"cannot reach it ({error.__class__.__name__}: {error})") from None
    with client:
        yield client


__all__ = ["check_scheduler", "connect"]
