"""Atomic file output: a file is either absent, or complete; never half-written."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from collections.abc import Iterator

from ..errors import UserError, at, first_line


@contextlib.contextmanager
def atomic_path(target: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``target``; on success it is fsynced, given the permissions
    of a newly created file (0666 less the umask) and renamed onto ``target`` in one step, on
    failure it is removed. A failure to write (disk full, read-only or missing permission) is a
    one-line :class:`UserError` naming ``target``; ``target`` is then left as it was."""
    target = Path(target)
    with _writing(target):
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
        os.close(fd)
        try:
            yield Path(tmp)
            with open(tmp, "rb+") as handle:
                os.fsync(handle.fileno())
            os.chmod(tmp, 0o666 & ~_umask())
            os.replace(tmp, target)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)


@contextlib.contextmanager
def _writing(target: Path) -> Iterator[None]:
    """Turn an OSError raised while writing ``target`` into a :class:`UserError`; the file it names
    is said unless it lies beside ``target`` (the temporary file, or ``target`` itself), however
    either path is written (relative or absolute)."""
    try:
        yield
    except OSError as exc:
        beside = exc.filename and Path(os.path.abspath(exc.filename)).parent == Path(os.path.abspath(target)).parent
        other = f" ({exc.filename})" if exc.filename and not beside else ""
        raise UserError(f"cannot write: {exc.strerror or first_line(exc)}{other}", at(target)) from None


def _umask() -> int:
    """The process's umask (read by setting it, then restoring it)."""
    mask = os.umask(0)
    os.umask(mask)
    return mask
