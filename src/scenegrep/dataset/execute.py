"""Executors: run one function over many work items, in this process, in a local process
pool, or on a Ray cluster, yielding each result as soon as it is ready.

Every executor is a generator of ``(item number, result)`` pairs in completion order.
Closing it early (an exception or Ctrl-C in the caller) cancels the work not yet started
and stops the workers; results already yielded stay with the caller. The function and
its items must be picklable; the function must be defined at module level.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any

from ..errors import UserError

ENGINES = ("local", "ray")


def default_jobs() -> int:
    """All cores this process may use."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def run_all(
    function: Callable[[Any], Any],
    items: Sequence[Any],
    jobs: int | None = None,
    engine: str = "local",
    address: str | None = None,
) -> Iterator[tuple[int, Any]]:
    """Apply ``function`` to every item with the chosen engine (``jobs`` workers; default all
    cores; 1 runs in this process); yields (index, result) as results arrive."""
    jobs = jobs or default_jobs()
    if jobs < 1:
        raise UserError(f"--jobs must be at least 1 (got {jobs})")
    if engine == "ray":
        return _ray(function, items, jobs, address)
    if engine != "local":
        raise UserError(f"unknown engine {engine!r}; choose one of {', '.join(ENGINES)}")
    if jobs == 1 or len(items) <= 1:
        return _serial(function, items)
    return _processes(function, items, jobs)


def _serial(function: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[tuple[int, Any]]:
    for number, item in enumerate(items):
        yield number, function(item)


PR_SET_PDEATHSIG = 1
"""Linux ``prctl`` option: the signal the kernel sends a process when its parent dies."""


def _start_worker(parent: int) -> None:
    """Workers leave Ctrl-C to the parent, which stops them after keeping what is done; and they
    die with the parent ``parent`` (a pid), even when it is killed with SIGKILL: Linux sends them
    SIGKILL then (``PR_SET_PDEATHSIG``). A parent gone before that was set up ends the worker here."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) != 0:
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG) failed")
    if os.getppid() != parent:
        os._exit(1)


def _processes(function: Callable[[Any], Any], items: Sequence[Any], jobs: int) -> Iterator[tuple[int, Any]]:
    """A pool of forked processes: they inherit what the parent has loaded (a compiled query).
    The workers start (fork) here, before the caller goes on to open files or databases."""
    context = multiprocessing.get_context("fork")
    pool = ProcessPoolExecutor(
        min(jobs, len(items)), mp_context=context, initializer=_start_worker, initargs=(os.getpid(),)
    )
    pending = {pool.submit(function, item): number for number, item in enumerate(items)}
    return _completed(pool, pending)


def _completed(pool: ProcessPoolExecutor, pending: dict[Future, int]) -> Iterator[tuple[int, Any]]:
    try:
        while pending:
            done, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                yield pending.pop(future), future.result()
    finally:
        _stop(pool, pending)


def _stop(pool: ProcessPoolExecutor, pending: dict[Future, int]) -> None:
    """Shut the pool down; if work is still pending (an interruption), kill the workers."""
    if not pending:
        pool.shutdown(wait=True)
        return
    processes = list(getattr(pool, "_processes", {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.kill()
    for process in processes:
        process.join()


def _ray(
    function: Callable[[Any], Any], items: Sequence[Any], jobs: int, address: str | None
) -> Iterator[tuple[int, Any]]:
    """Ray tasks, one per item; starts a local Ray instance with ``jobs`` CPUs unless ``address``
    names a running cluster (``auto`` finds one started with ``ray start``)."""
    try:
        import ray
    except ImportError:
        raise UserError("--engine ray needs Ray: pip install 'scenegrep[ray]'") from None
    started = not ray.is_initialized()
    if started:
        options: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False, "logging_level": "ERROR"}
        if address is None:
            options["num_cpus"] = jobs
        else:
            options["address"] = address
        try:
            ray.init(**options)
        except (ConnectionError, RuntimeError, ValueError) as exc:
            where = f"at {address}" if address else "locally"
            raise UserError(f"cannot start Ray {where}: {str(exc).splitlines()[0]}") from None
    remote = ray.remote(function)
    pending: dict[Any, int] = {}
    try:
        pending = {remote.remote(item): number for number, item in enumerate(items)}
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                yield pending.pop(ref), ray.get(ref)
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
        if started:
            ray.shutdown()
