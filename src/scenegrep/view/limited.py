"""A dataset query with a time limit, for ``scenegrep serve``: the run (compile, plan, query)
happens in a child process that leads its own process group, so that when the limit passes
the child and every worker it started are killed at once, and the server goes on.

The child is forked from a fork server (``multiprocessing``'s forkserver, which preloads this
module), never from the threaded server itself, and works in the dataset folder, so relative
file options (``vocabulary``) resolve there.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Any

from ..dataset.queries import QuerySpec, compiled
from ..dataset.run import RunOptions, run_query
from ..errors import UserError
from .guard import Refused, dataset_file

PRELOAD = (__name__, "pyarrow.dataset", "scenegrep.spre", "scenegrep.scene", "scenegrep.scenario", "scenegrep.label")
"""Modules the fork server imports once, so that a query's child starts with them (a cold
``pyarrow.dataset``, the first Parquet read, alone takes 1.5 s)."""
_CONTEXT = multiprocessing.get_context("forkserver")
_CONTEXT.set_forkserver_preload(list(PRELOAD))
_RUNNING: set[int] = set()
"""Process ids of the query children not yet reaped (each leads its own process group)."""
_REAPING = threading.Lock()
"""Held while a child is killed and reaped, so that no group id is killed after its reuse."""


EXIT_GRACE = 5.0
"""Seconds a child that answered (or died) may take to exit before its group is killed."""


class QueryTimeout(Exception):
    """The query ran past its time limit (and was stopped)."""


def run_limited(root: Path, spec: QuerySpec, jobs: int | None, limit: float) -> dict[str, Any]:
    """The run's answer (:func:`answer`) computed in a child process within ``limit`` seconds.

    Raises :class:`UserError` for an error in the query, :class:`QueryTimeout` when the limit
    passed (the child and its workers are killed), RuntimeError when the child died."""
    receive, send = _CONTEXT.Pipe(duplex=False)
    child = _CONTEXT.Process(target=_child, args=(send, root, spec, jobs), name="scenegrep-serve-query")
    child.start()
    _RUNNING.add(child.pid)
    send.close()
    grace = 0.0
    try:
        if not receive.poll(limit):
            raise QueryTimeout(f"the query ran longer than {limit:g} s and was stopped")
        grace = EXIT_GRACE
        kind, value = receive.recv()
    except EOFError:
        raise RuntimeError("the query's process ended without an answer") from None
    finally:
        receive.close()
        _reap(child, grace)
    if kind == "error":
        raise UserError(value)
    return value


def _reap(child: Any, grace: float) -> None:
    """Let the child exit within ``grace`` seconds, then kill what is left of its group."""
    with _REAPING:
        child.join(grace)
        _kill_group(child.pid)
        child.join()
        _RUNNING.discard(child.pid)


def start_fork_server() -> None:
    """Start the fork server (importing :data:`PRELOAD`) now rather than at the first query."""
    from multiprocessing import forkserver

    forkserver.ensure_running()


def stop_all() -> None:
    """Kill every running query (children in their own process groups do not get the terminal's
    Ctrl-C); for a server that stops while a query runs."""
    with _REAPING:
        for pid in _RUNNING:
            _kill_group(pid)


def _kill_group(pid: int | None) -> None:
    """Kill the child's process group (the child, and the workers it forked). While any member
    lives the group id cannot be reused; once none does, nothing has that group id but a
    process that has since made itself a group leader with the same id (not guarded against)."""
    if pid is not None:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(pid, signal.SIGKILL)


def _child(send: Connection, root: Path, spec: QuerySpec, jobs: int | None) -> None:
    """Run the query in the dataset folder and send ``("ok", answer)`` or ``("error", line)``;
    a program's ``param map`` must name a file inside the dataset, as file options do."""
    os.setsid()
    os.chdir(root)
    try:
        named = _program_map(compiled(spec))
        if named is not None:
            dataset_file(root, named, "param map")
        message: tuple[str, Any] = ("ok", answer(run_query(root, spec, RunOptions(jobs=jobs))))
    except UserError as exc:
        message = ("error", exc.one_line())
    except Refused as exc:
        message = ("error", exc.reason)
    send.send(message)
    send.close()


def _program_map(query: Any) -> str | None:
    """The file a compiled scene or scenario program's ``param map`` names, if any."""
    program = getattr(getattr(query, "scene", query), "program", None)
    return getattr(program, "map_path", None)


def answer(results: Any) -> dict[str, Any]:
    """What the page gets of a run: its id, status, counts, report link and matches (each
    with the link of its view)."""
    from urllib.parse import quote

    matches = results.matches.to_pylist()
    for row in matches:
        row["href"] = f"/view/{quote(row['trace_id'])}?run={results.run_id}#match={row['match']}"
    return {
        "run_id": results.run_id,
        "status": results.status,
        "counts": results.counts(),
        "report": f"/report/{results.run_id}",
        "matches": matches,
    }
