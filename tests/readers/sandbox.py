"""A sandbox for fuzzing the readers: runs ``scenegrep ARGS`` in a forked child limited to
2 GB of address space and 60 s, and reports its exit code and standard error.

Run as ``python -m tests.readers.sandbox``: it imports scenegrep once, then reads one JSON list of
command-line arguments per line on stdin and answers one JSON line per request,
``{"exit": int | null, "signal": int | null, "stderr": str, "seconds": float}``. The child of each
request is forked from this small process (a few hundred MB of address space), so the 2 GB limit
is the reader's, not the test runner's.
"""

from __future__ import annotations

import json
import os
import resource
import signal
import sys
import tempfile
import time
import traceback

MEMORY_LIMIT = 2 * 1024**3
"""Address space a reader may use (bytes)."""
TIME_LIMIT = 60
"""Seconds a reader may take."""


def _child(argv: list[str], stderr_fd: int) -> None:
    """Run one command line with the limits in place; never returns."""
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    signal.alarm(TIME_LIMIT)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(stderr_fd, 2)
    code = 1
    try:
        from scenegrep.cli.main import main

        code = main(argv)
    except BaseException:  # noqa: BLE001 - a traceback is what the fuzz suite looks for
        traceback.print_exc()
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)


def run(argv: list[str]) -> dict[str, object]:
    """Fork, run ``scenegrep argv`` in the child under the limits, and describe the outcome."""
    with tempfile.TemporaryFile() as err:
        start = time.monotonic()
        pid = os.fork()
        if pid == 0:
            _child(argv, err.fileno())
        _, status = os.waitpid(pid, 0)
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
    return {
        "exit": os.waitstatus_to_exitcode(status) if os.WIFEXITED(status) else None,
        "signal": os.WTERMSIG(status) if os.WIFSIGNALED(status) else None,
        "stderr": text,
        "seconds": time.monotonic() - start,
    }


def serve() -> None:
    """Answer requests from stdin until it closes."""
    import scenegrep.cli.main  # noqa: F401 - imported once, shared by every forked child
    import scenegrep.summary  # noqa: F401

    for line in sys.stdin:
        print(json.dumps(run(json.loads(line))), flush=True)


if __name__ == "__main__":
    serve()
