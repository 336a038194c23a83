"""Where the units run: a process pool on this machine, or a Dask cluster (an optional extra).

Both pools have one interface, used by :func:`align.production.batch.run_units`: ``submit(fn, arg)`` returns
a future, ``wait(futures)`` returns the ones done (at least one), ``future.result()`` the value or the
worker's exception. The process pool is :class:`concurrent.futures.ProcessPoolExecutor` (workers ignore
Ctrl-C: the batch that started them stops them), its workers forks of the batch's process where that is
safe (they start with the jobs' modules imported), else forked by a fork server that imported them once.
The Dask pool is a ``dask.distributed.Client``, on a running scheduler (``tcp://host:8786``) or on a local
cluster of ``workers`` processes with one thread each (``"local"``); Dask is imported only then.

A cluster's workers must see the manifest's files and the output folder under the same absolute
paths (a shared file system): each unit reads its inputs and writes its result where it runs.

Public names
------------
ProcessPool, DaskPool, make_pool, BrokenPool, release_memory
"""

from __future__ import annotations

import concurrent.futures as cf
import gc
import multiprocessing as mp
import os
import signal
import sys
import threading
from typing import Any

from align.errors import InputError

#: seconds to wait for a Dask scheduler to answer
CONNECT_TIMEOUT = 10.0
#: the pool's workers died (a crash, killed): the units it held are lost, the pool is made again
BrokenPool = cf.BrokenExecutor


_TRIM: list = []


def release_memory() -> None:
    """Hand the heap's free pages back to the system after a unit (glibc's ``malloc_trim(0)``; nothing elsewhere).

    A worker runs thousands of units, each allocating and freeing arrays of every size: glibc keeps the freed
    pages, and a worker's resident memory crept up by about 20 KB per unit (from 157 to 177 MB over 1,000 units of
    bench/bench_batch.py's lot run one after another in one process, measured once with psutil); returned after each
    unit, it stayed within 160-170 MB, and the 1,000 units took 52 s instead of 54 s.
    """
    if not _TRIM:
        try:
            import ctypes

            _TRIM.append(ctypes.CDLL(None).malloc_trim if sys.platform.startswith("linux") else None)
        except (OSError, AttributeError):
            _TRIM.append(None)
    if _TRIM[0] is not None:
        _TRIM[0](0)


def _ignore_interrupt(preload: tuple[str, ...] = ()) -> None:
    """A worker's start: Ctrl-C is the batch's to handle; the modules its units need imported (already there when
    the fork server preloaded them)."""
    import importlib

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in preload:
        try:
            importlib.import_module(name)
        except ImportError:  # the unit that needs it says why
            pass


def _fork_is_safe() -> bool:
    """Whether a worker may be a fork of this process: on Linux, with no other thread running and numba's
    parallel layer not started (a fork of a process whose OpenMP threads ran aborts in GNU OpenMP)."""
    if sys.platform != "linux" or "fork" not in mp.get_all_start_methods() or threading.active_count() > 1:
        return False
    parallel = sys.modules.get("numba.np.ufunc.parallel")
    return parallel is None or getattr(parallel, "_is_initialized", True) is False


class ProcessPool:
    """``workers`` processes on this machine (:class:`concurrent.futures.ProcessPoolExecutor`).

    A worker is a fork of this process when that is safe (:func:`_fork_is_safe`): it starts with every module
    this process imported (the jobs', to build their options), at no cost. Otherwise a fork server (spawn where
    it is missing) starts the workers: it imports ``preload`` (the worker's and the jobs' modules) once, and
    every worker it forks inherits them; :meth:`prestart` then starts them while the batch prepares its units.
    """

    def __init__(self, workers: int, preload: tuple[str, ...] = ()) -> None:
        self.workers = max(1, int(workers))
        self.preload = tuple(preload)
        self._ex: cf.ProcessPoolExecutor | None = None

    def prestart(self) -> ProcessPool:
        """Start the workers ahead of the first unit where that helps: a fork server's, which import the jobs'
        modules meanwhile (forked workers start with the first unit, with what this process imported by then)."""
        if not _fork_is_safe():
            self.start()
        return self

    def start(self) -> ProcessPool:
        """Start the workers (once); :meth:`close` stops them."""
        if self._ex is not None:
            return self
        context: mp.context.BaseContext
        if _fork_is_safe():
            context = mp.get_context("fork")
        else:
            # forkserver (spawn where it is missing): a forked worker inherits a parent's OpenMP threads (numba's
            # parallel kernels once they have run), which GNU OpenMP aborts on; the fork server runs no kernel
            method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
            context = mp.get_context(method)
            if method == "forkserver" and self.preload:  # taken when this process starts its fork server (once)
                context.set_forkserver_preload(["__main__", *self.preload])
        self._ex = cf.ProcessPoolExecutor(self.workers, mp_context=context, initializer=_ignore_interrupt,
                                          initargs=(self.preload,))
        frozen = context.get_start_method() == "fork"
        if frozen:  # the objects a forked worker inherits are left out of its garbage collections (no copy on write)
            gc.freeze()
        try:
            for _ in range(self.workers):  # the workers started now (a fork server's: one per submission)
                self._ex.submit(int)
        finally:
            if frozen:
                gc.unfreeze()
        return self

    def __enter__(self) -> ProcessPool:
        return self.start()

    def __exit__(self, *exc) -> None:
        self.close(cancel=exc[0] is not None)

    def close(self, cancel: bool = False) -> None:
        """Stop the workers; with ``cancel``, drop the units not started (a running unit finishes)."""
        if self._ex is not None:
            self._ex.shutdown(wait=not cancel, cancel_futures=cancel)
            self._ex = None

    def restart(self) -> None:
        """A new pool when the workers died (once: the other units the dead pool held fail the same way)."""
        if self._ex is None:
            self.start()
            return
        try:
            self._ex.submit(int).cancel()
        except cf.BrokenExecutor:
            self.close(cancel=True)
            self.start()

    def submit(self, fn, arg):
        return self._ex.submit(fn, arg)

    def wait(self, futures) -> set:
        done, _ = cf.wait(futures, return_when=cf.FIRST_COMPLETED)
        return done

    @property
    def where(self) -> str:
        return f"{self.workers} local process{'es' if self.workers != 1 else ''}"


class DaskPool:
    """A Dask distributed client: on the scheduler at ``address``, or on a local cluster (``"local"``)."""

    def __init__(self, address: str, workers: int | None = None) -> None:
        self.address, self.workers = address, workers
        self._client: Any = None
        self._cluster: Any = None

    def prestart(self) -> DaskPool:
        """Nothing before the first unit: a cluster is reached when the units run (:meth:`__enter__`)."""
        return self

    def __enter__(self) -> DaskPool:
        try:
            from dask import distributed
        except ImportError:
            raise InputError("Dask is not installed: pip install 'imu-align[cluster]'", "{scheduler}") from None
        self._distributed = distributed
        try:
            if self.address == "local":
                self._cluster = distributed.LocalCluster(n_workers=self.workers or os.cpu_count() or 1,
                                                         threads_per_worker=1, processes=True,
                                                         dashboard_address=None, silence_logs=50)
                self._client = distributed.Client(self._cluster)
            else:
                self._client = distributed.Client(self.address, timeout=CONNECT_TIMEOUT)
        except ValueError as exc:  # not an address at all ('bogus': no port)
            self.close()
            raise InputError(f"'{self.address}' is not a Dask scheduler address ({' '.join(str(exc).split())[:120]}); "
                             "give tcp://HOST:PORT, or 'local'", "{scheduler}") from None
        except OSError as exc:  # no scheduler there (a timeout is an OSError too)
            self.close()
            raise InputError(f"cannot reach the Dask scheduler at {self.address} ({' '.join(str(exc).split())[:160]}); "
                             "start it (dask scheduler) or check the address", "{scheduler}") from None
        return self

    def __exit__(self, *exc) -> None:
        self.close(cancel=exc[0] is not None)

    def close(self, cancel: bool = False) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None

    def restart(self) -> None:  # Dask reschedules the work of a lost worker itself
        pass

    def submit(self, fn, arg):
        return self._client.submit(fn, arg, pure=False)

    def wait(self, futures) -> set:
        done = self._distributed.wait(list(futures), return_when="FIRST_COMPLETED").done
        return set(done)

    @property
    def where(self) -> str:
        if self.address == "local":
            return f"a local Dask cluster of {self.workers} workers"
        return f"the Dask scheduler at {self.address}"


def make_pool(workers: int, scheduler: str | None = None, preload: tuple[str, ...] = ()) -> ProcessPool | DaskPool:
    """A process pool of ``workers`` (``preload``: the modules its units need), or a Dask pool on ``scheduler``
    (``"local"``: a local cluster of ``workers``)."""
    if scheduler is None:
        return ProcessPool(workers, preload)
    return DaskPool(scheduler, workers)
