"""Where the runs go: this process, or a dask.distributed cluster.

``client`` everywhere in :mod:`rodmol.calibrate` is one of

* ``None``: a LocalCluster started for the call (one single-threaded worker
  process per core, at most ``n_workers``) and closed after it;
* a ``distributed.Client`` (yours: it is left open) or a scheduler address
  such as ``"tcp://10.0.0.5:8786"`` (a real cluster);
* ``"serial"``: run in this process, one after the other.

Each worker compiles nothing: numba's machine code is cached on disk next to
the package, so a new worker only loads it (about a second, once).
"""

import contextlib
import os
import pickle
import sys
import time
import warnings

from ..errors import ParameterError

SERIAL = "serial"


class Serial:
    """Runs tasks in this process."""

    workers = 1

    def map(self, function, items, progress=None, failed=None):
        """``function(item)`` for each item, in order; see :meth:`Dask.map` for ``failed``."""
        out = []
        for i, item in enumerate(items):
            try:
                out.append(function(item))
            except Exception as exc:  # noqa: BLE001 (one item's failure, returned in its place)
                if failed is None:
                    raise
                out.append(failed(item, exc))
            if progress:
                progress(i + 1, len(items))
        return out


class Dask:
    """Runs tasks on a dask.distributed client, one task per item."""

    def __init__(self, client):
        self.client = client
        self.workers = max(1, len(client.scheduler_info().get("workers", {})))

    def map(self, function, items, progress=None, failed=None):
        """``function(item)`` for each item, in the items' order. A worker that dies
        (killed, out of memory) has its tasks rerun on the others by the scheduler
        (up to its ``allowed-failures``); a task that still fails, by raising or by
        killing every worker it ran on, gives ``failed(item, exception)`` in its
        place if ``failed`` is given, else its exception is raised here."""
        from distributed import as_completed

        items = list(items)
        futures = self.client.map(function, items, pure=False)
        for done, _ in enumerate(as_completed(futures), start=1):
            if progress:
                progress(done, len(items))
        if failed is None:
            return self.client.gather(futures)
        return [future.result() if future.status == "finished" else failed(item, future.exception())
                for item, future in zip(items, futures)]


def cores():
    """Cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@contextlib.contextmanager
def executor(client=None, n_workers=None):
    """A :class:`Serial` or :class:`Dask` executor for ``client`` (see the module docstring)."""
    if client == SERIAL:
        yield Serial()
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        if client is not None:
            raise ParameterError("a dask client or scheduler address needs dask.distributed: "
                                 "pip install 'rodmol[calibrate]'") from None
        warnings.warn("dask.distributed is not installed: running serially "
                      "(pip install 'rodmol[calibrate]' for parallel runs)", RuntimeWarning, stacklevel=3)
        yield Serial()
        return
    if client is None:
        workers = max(1, min(cores(), n_workers or cores()))
        # One thread per worker: the solver is single-threaded and the
        # machine's cores are the workers (BLAS threads are pinned to 1 by
        # distributed's pre-spawn environment).
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                          dashboard_address=None, silence_logs=50) as cluster, Client(cluster) as own:
            yield Dask(own)
        return
    if isinstance(client, str):
        with Client(client) as own:
            yield Dask(own)
        return
    if not isinstance(client, Client):
        raise ParameterError(f"`client` must be None, 'serial', a scheduler address or a "
                             f"distributed.Client, got {client!r}")
    yield Dask(client)


def check_picklable(spec):
    """Raise a ParameterError if ``spec`` cannot be sent to another process."""
    try:
        pickle.dumps(spec)
    except (pickle.PicklingError, TypeError, AttributeError) as exc:
        raise ParameterError(f"this scenario cannot run on dask workers: {exc}") from None


class ProgressLine:
    """``progress(done, total)`` printing ``label: done/total runs`` with rates to a stream."""

    def __init__(self, label, stream=None):
        self.label, self.stream = label, stream or sys.stderr
        self.start = time.perf_counter()

    def __call__(self, done, total):
        wall = time.perf_counter() - self.start
        self.stream.write(f"\r{self.label}: {done}/{total} runs, {wall:.1f} s"
                          + ("\n" if done == total else ""))
        self.stream.flush()
