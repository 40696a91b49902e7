"""Progress bars: on standard error, and only when it is a terminal.

Every progress bar of scenegrep is made here. A bar is shown only when standard error is a
terminal and the user did not ask for quiet: written into a redirected file or a pipe, a bar's
carriage returns and redraws would be noise in the log (``scenegrep label ... 2> log``).
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from typing import Any


def shown(quiet: bool = False) -> bool:
    """Whether a progress bar is drawn: not ``quiet`` and standard error is a terminal."""
    if quiet:
        return False
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError, OSError):  # a closed or replaced stream is no terminal
        return False


def bar(iterable: Iterable[Any] | None = None, quiet: bool = False, **options: Any) -> Any:
    """A tqdm bar over ``iterable`` (or updated by hand) on standard error, disabled unless
    :func:`shown`; ``options`` are tqdm's (``total``, ``unit``, ``desc``, ...)."""
    from tqdm import tqdm

    return tqdm(iterable, file=sys.stderr, disable=not shown(quiet), **options)
