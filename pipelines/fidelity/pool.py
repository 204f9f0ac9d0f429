"""Run study jobs on local processes or a Dask cluster, and stop cleanly.

Every finished job is handed to a callback at once (the runner caches it
atomically), so an interruption loses only the jobs still running.  On
Ctrl-C (SIGINT) or SIGTERM the parent cancels what has not started, kills
its worker processes, keeps the rows that finished meanwhile and raises
:class:`StudyInterrupted`; a worker whose parent dies (even by SIGKILL,
which no handler sees) kills itself (Linux ``PR_SET_PDEATHSIG``, and a
watchdog thread that notices the reparenting elsewhere).
"""

from __future__ import annotations

import contextlib
import ctypes
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

from capture2notation.errors import PipelineError

__all__ = ["STOP_SIGNALS", "StudyInterrupted", "execute"]

log = logging.getLogger(__name__)

#: Seconds between a worker's checks that its parent is still alive: the
#: longest an orphan computes where ``PR_SET_PDEATHSIG`` is unavailable.
WATCHDOG_S = 0.5
#: Seconds the parent waits for killed workers to be reaped.
REAP_S = 1.0
#: Seconds to wait for the result of a Dask future that had already finished when interrupted.
DASK_FETCH_S = 1.0
#: Signals that stop a study cleanly (Ctrl-C, ``kill``).
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_PR_SET_PDEATHSIG = 1  # linux/prctl.h


class StudyInterrupted(PipelineError):
    """The study was stopped by a signal; finished jobs are cached.

    Attributes
    ----------
    signum : int
        The signal (``signal.SIGINT`` for Ctrl-C).
    """

    def __init__(self, message: str, signum: int):
        super().__init__(message)
        self.signum = signum


class _Stop(BaseException):
    """Raised in the main thread by the SIGTERM handler (as KeyboardInterrupt is by SIGINT)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


@contextlib.contextmanager
def stop_on_signals():
    """Turn SIGTERM into :class:`_Stop` in the main thread for the duration (SIGINT already raises)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, _frame):
        raise _Stop(signum)

    old = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def signal_of(exc: BaseException) -> int | None:
    """The stop signal an exception stands for, or None."""
    if isinstance(exc, KeyboardInterrupt):
        return int(signal.SIGINT)
    if isinstance(exc, _Stop):
        return exc.signum
    return None


def _worker_init(parent: int) -> None:
    """In each worker: die with the parent; leave Ctrl-C to the parent."""
    # A terminal's Ctrl-C reaches the whole process group; the parent decides
    # what to keep and kills the workers, so they must not unwind on their own.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)

    def watch():
        while os.getppid() == parent:
            threading.Event().wait(WATCHDOG_S)
        os._exit(1)  # orphaned: reparented to init or a subreaper

    threading.Thread(target=watch, name="c2n-parent-watchdog", daemon=True).start()


def _kill_pool(pool: ProcessPoolExecutor) -> None:
    procs = list((getattr(pool, "_processes", None) or {}).values())
    for p in procs:
        with contextlib.suppress(OSError, ValueError):
            p.kill()
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        with contextlib.suppress(OSError, ValueError, AssertionError):
            p.join(REAP_S)


def execute(
    fn: Callable,
    items: list,
    on_done: Callable,
    scheduler: str | None = None,
    workers: int = 1,
    timeout: float = 20.0,
    on_progress: Callable[[], None] = lambda: None,
) -> None:
    """Run ``fn(item)`` for every item and call ``on_done(i, result)`` as each finishes.

    Parameters
    ----------
    fn : callable
        A picklable function of one item.
    items : list
    on_done : callable
        ``(index into items, result)``; called in this process, in order of completion.
    scheduler : str, optional
        Dask scheduler address; local processes otherwise.
    workers : int
        Local processes (1 = run here, in this process).
    timeout : float
        Seconds to wait for the Dask scheduler.
    on_progress : callable
        Called after each ``on_done``.

    Raises
    ------
    KeyboardInterrupt, _Stop
        After the workers are stopped and every finished result was handed on.
    """
    if scheduler:
        _execute_dask(fn, items, on_done, scheduler, timeout, on_progress)
    elif workers <= 1 or len(items) <= 1:
        for i, item in enumerate(items):
            on_done(i, fn(item))
            on_progress()
    else:
        _execute_local(fn, items, on_done, workers, on_progress)


def _execute_local(fn, items, on_done, workers, on_progress) -> None:
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_worker_init, initargs=(os.getpid(),))
    index = {pool.submit(fn, item): i for i, item in enumerate(items)}
    pending = set(index)
    try:
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in done:
                on_done(index[fut], fut.result())
                on_progress()
    except BaseException:
        # Keep what finished while we were interrupted, then stop at once:
        # the jobs still running would take minutes and their rows are lost anyway.
        for fut in [f for f in pending if f.done() and not f.cancelled() and f.exception() is None]:
            on_done(index[fut], fut.result())
        _kill_pool(pool)
        raise
    pool.shutdown(wait=True)


def _execute_dask(fn, items, on_done, scheduler, timeout, on_progress) -> None:
    try:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise PipelineError(
            f"--scheduler {scheduler}: a Dask scheduler needs dask.distributed: pip install 'capture2notation[cluster]'"
        ) from None

    try:
        client = Client(scheduler, timeout=f"{timeout}s")
    except (OSError, TimeoutError) as exc:
        raise PipelineError(f"cannot reach the Dask scheduler at {scheduler!r}: {exc}") from None
    futures: list = []
    index: dict = {}
    handled: set = set()
    try:
        futures = client.map(fn, items, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        for fut in dask_completed(futures):
            on_done(index[fut.key], fut.result())
            handled.add(fut.key)
            on_progress()
    except BaseException:
        for fut in futures:
            if fut.key not in handled and fut.status == "finished":
                try:
                    row = fut.result(timeout=DASK_FETCH_S)
                except Exception as exc:  # the job is simply rerun next time
                    log.warning("finished Dask job %s not kept: %s", fut.key, exc)
                    continue
                on_done(index[fut.key], row)
        # The cluster is not ours to kill: cancel our jobs so its workers stop computing them.
        try:
            client.cancel(futures, force=True)
        except Exception as exc:  # we are stopping anyway
            log.warning("could not cancel the Dask jobs: %s", exc)
        raise
    finally:
        client.close()
