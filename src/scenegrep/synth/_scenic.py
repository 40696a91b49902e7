"""Running the real Scenic for the synthetic-data generators: inputs, the road map, seeding, errors.

Shared by :mod:`.scenic_scenes` (static scenes) and :mod:`.simulate` (simulations).

Scenic parses OpenDRIVE in seconds and caches the result in a ``.snet`` file beside the map. So
that the cache is never written beside the user's file (which may be read-only), Scenic reads
a copy of the map kept in the user cache (``scenic-maps/<digest>-scenic<version>/``), where its
``.snet`` lands; later compiles of any program on the same map load it in a fraction of a second.

Scenic is imported inside the functions (about a second), never when this module is imported.
"""

from __future__ import annotations

import contextlib
import random
import shutil
import traceback
import warnings
from collections.abc import Iterator, Mapping
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np

from ..cache import cache_dir, file_digest
from ..errors import SourceLocation, UserError, at, first_line
from ..model.geometry import normalize_angle


def checked_inputs(program: str | Path, map_path: str | Path) -> tuple[Path, Path]:
    """The program and the OpenDRIVE map as paths; a missing file or a map that is not ``.xodr``
    is a :class:`UserError`."""
    program, map_path = Path(program), Path(map_path)
    _check_file(program, "a Scenic program")
    _check_file(map_path, "an OpenDRIVE map")
    if map_path.suffix.lower() != ".xodr":
        raise UserError("not an OpenDRIVE map: expected a .xodr file", at(map_path))
    return program, map_path


def _check_file(path: Path, what: str) -> None:
    if not path.is_file():
        raise UserError(f"no such file (expected {what})", at(path))


def map_params(map_path: Path) -> dict[str, Any]:
    """The global parameters that give Scenic the map: the cached copy, or (when the cache
    cannot be written) the map itself with Scenic's ``.snet`` cache writing turned off."""
    try:
        return {"map": str(_cached_map(map_path))}
    except OSError:
        return {"map": str(map_path), "map_options": {"writeCache": False}}


def _cached_map(map_path: Path) -> Path:
    """A copy of the map in the user cache, beside which Scenic may write its ``.snet`` cache."""
    from ..writers.atomic import atomic_path  # the writers package imports pyarrow and shapely

    folder = cache_dir() / "scenic-maps" / f"{file_digest(map_path)[:20]}-scenic{version('scenic')}"
    copy = folder / f"{map_path.stem}.xodr"
    if not copy.is_file():
        with atomic_path(copy) as tmp:
            shutil.copyfile(map_path, tmp)
    return copy


def compile_program(program: Path, params: Mapping[str, Any]) -> Any:
    """The program compiled by Scenic in 2-D mode with the given global parameters (a Scenic
    ``Scenario``); errors in the program are :class:`UserError`\\ s (see :func:`scenic_errors`)."""
    import scenic
    from scenic.formats.opendrive.xodr_parser import OpenDriveWarning

    with scenic_errors(program), warnings.catch_warnings():
        warnings.simplefilter("ignore", OpenDriveWarning)
        return scenic.scenarioFromFile(str(program), mode2D=True, params=dict(params))


def seed_scenic(seed: int) -> None:
    """Seed Scenic's sources of randomness (``random`` and ``numpy.random``)."""
    random.seed(seed)
    np.random.seed(seed)


def scenic_version() -> str:
    """The installed Scenic's version string."""
    return version("scenic")


@contextlib.contextmanager
def scenic_errors(program: Path) -> Iterator[None]:
    """Turn errors of the user's program into one-line :class:`UserError`\\ s located in it.

    Scenic's own errors (syntax, invalid scenario) and scenes rejected too often always are; any
    other exception is when it was raised while running a line of the program (a ``NameError``
    at the top level, an ``AttributeError`` inside a behaviour, ...), located at the innermost
    such line. Exceptions that never passed through the program are scenegrep's or Scenic's bugs
    and propagate unchanged.
    """
    from scenic.core.distributions import RejectionException
    from scenic.core.errors import ScenicError

    try:
        yield
    except UserError:
        raise
    except RejectionException as exc:
        raise UserError(f"Scenic could not generate a scene: {first_line(exc)}", at(program)) from None
    except ScenicError as exc:
        message = f"Scenic rejected the program: {type(exc).__name__}: {first_line(exc)}"
        raise UserError(message, _location(exc, program) or at(program)) from None
    except Exception as exc:
        location = _location(exc, program)
        if location is None:
            raise
        raise UserError(f"{type(exc).__name__}: {first_line(exc)}", location) from None


def _location(exc: BaseException, program: Path) -> SourceLocation | None:
    """Where in the program an exception points: its own line and (1-based) column when it is
    a syntax error in the program, else the innermost traceback frame running the program."""
    target = program.resolve()
    filename = getattr(exc, "filename", None)
    line = getattr(exc, "lineno", None)
    if line is not None and (filename is None or Path(filename).resolve() == target):
        return at(program, line, getattr(exc, "offset", None))
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename).resolve() == target]
    if not frames:
        return None
    innermost = frames[-1]
    return at(program, innermost.lineno, None if innermost.colno is None else innermost.colno + 1)


def scenic_headings(values: np.ndarray) -> np.ndarray:
    """Scenic headings (radians) in (-pi, pi]; values already there are kept bit for bit."""
    return np.where((values > -np.pi) & (values <= np.pi), values, normalize_angle(values))
