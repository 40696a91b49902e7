"""The inputs of ``label`` and ``info``: folders searched as the query commands search them,
and an unreadable input reported in one line while the others go on.

A folder of trace files is replaced by the inputs found in it by
:func:`scenegrep.dataset.ingest.discover` (the query commands' and ``ingest``'s search), so a
file there that cannot be read is named and the rest are read. One path that is not such a
folder is read as before: its error is the command's (one line, exit code 2), as in the query
commands (:mod:`scenegrep.cli.dataset_run`).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

from .exit_codes import EXIT_SOME_FAILED


def each_input(paths: list[str], work: Callable[[str], None]) -> int:
    """Call ``work`` on every input under ``paths`` (see the module docstring). Over a folder or
    several paths, an input that cannot be found or on which ``work`` raises is printed on
    stderr as ``scenegrep: failed: NAME: ERROR`` and the others go on; the exit code is then
    :data:`EXIT_SOME_FAILED` if any failed, else 0. Over one path that is not a folder, its
    error is raised."""
    from ..errors import failure_text

    inputs, failed = _expand(paths)
    if inputs == paths and len(paths) == 1:
        work(paths[0])
        return 0
    for path in inputs:
        try:
            work(path)
        except BrokenPipeError:  # the reader of stdout left (`| head`): stop, nothing failed
            raise
        except Exception as exc:  # one bad input must not stop the others
            failed.append((path, failure_text(exc, path)))
    for path, error in failed:
        print(f"scenegrep: failed: {Path(path).name}: {error}", file=sys.stderr)
    return EXIT_SOME_FAILED if failed else 0


def is_one_input(path: str) -> bool:
    """Whether ``path`` is one input (a file, ``-``, a recording directory such as an Argoverse 2
    log), not a folder of inputs to search."""
    from ..dataset.ingest import directory_format

    return not Path(path).is_dir() or directory_format(Path(path)) is not None


def _expand(paths: list[str]) -> tuple[list[str], list[tuple[str, str]]]:
    """The inputs under ``paths``, in order, and the files found in folders that look like
    inputs but cannot be read (path, one-line error). A path that is not a folder (a file,
    ``-``, an Argoverse 2 log) is kept as given; a folder with no inputs is a user error."""
    from ..dataset.ingest import discover
    from ..errors import UserError, at

    inputs: list[str] = []
    failed: list[tuple[str, str]] = []
    for path in paths:
        if is_one_input(path):
            inputs.append(path)
            continue
        sources, bad = discover([path])
        if not sources and not bad:
            raise UserError("a folder without trace files", at(path))
        inputs.extend(source.path for source in sources)
        failed.extend(bad)
    return inputs, failed
