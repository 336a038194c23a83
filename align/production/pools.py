"""Where the units run: a process pool on this machine, or a Dask cluster (an optional extra).

Both pools have one interface, used by :func:`align.production.batch.run_units`: ``submit(fn, arg)`` returns
a future, ``wait(futures)`` returns the ones done (at least one), ``future.result()`` the value or the
worker's exception. The process pool is :class:`concurrent.futures.ProcessPoolExecutor` (workers ignore
Ctrl-C: the batch that started them stops them). The Dask pool is a ``dask.distributed.Client``, on
a running scheduler (``tcp://host:8786``) or on a local cluster of ``workers`` processes with one
thread each (``"local"``); Dask is imported only then.

A cluster's workers must see the manifest's files and the output folder under the same absolute
paths (a shared file system): each unit reads its inputs and writes its result where it runs.

Public names
------------
ProcessPool, DaskPool, make_pool, BrokenPool
"""

from __future__ import annotations

import concurrent.futures as cf
import multiprocessing as mp
import os
import signal

from align.errors import InputError

#: seconds to wait for a Dask scheduler to answer
CONNECT_TIMEOUT = 10.0
#: the pool's workers died (a crash, killed): the units it held are lost, the pool is made again
BrokenPool = cf.BrokenExecutor


def _ignore_interrupt() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class ProcessPool:
    """``workers`` processes on this machine (:class:`concurrent.futures.ProcessPoolExecutor`)."""

    def __init__(self, workers: int) -> None:
        self.workers = max(1, int(workers))
        self._ex: cf.ProcessPoolExecutor | None = None

    def __enter__(self) -> ProcessPool:
        # forkserver (spawn where it is missing): a forked worker inherits a parent's OpenMP threads (numba's
        # parallel kernels once they have run), which GNU OpenMP aborts on
        method = "forkserver" if "forkserver" in mp.get_all_start_methods() else "spawn"
        self._ex = cf.ProcessPoolExecutor(self.workers, mp_context=mp.get_context(method), initializer=_ignore_interrupt)
        return self

    def __exit__(self, *exc) -> None:
        self.close(cancel=exc[0] is not None)

    def close(self, cancel: bool = False) -> None:
        """Stop the workers; with ``cancel``, drop the units not started (a running unit finishes)."""
        if self._ex is not None:
            self._ex.shutdown(wait=not cancel, cancel_futures=cancel)
            self._ex = None

    def restart(self) -> None:
        """A new pool when the workers died (once: the other units the dead pool held fail the same way)."""
        try:
            self._ex.submit(int).cancel()
        except cf.BrokenExecutor:
            self.close(cancel=True)
            self.__enter__()

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
        self._client = self._cluster = None

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


def make_pool(workers: int, scheduler: str | None = None) -> ProcessPool | DaskPool:
    """A process pool of ``workers``, or a Dask pool on ``scheduler`` (``"local"``: a local cluster of ``workers``)."""
    if scheduler is None:
        return ProcessPool(workers)
    return DaskPool(scheduler, workers)
