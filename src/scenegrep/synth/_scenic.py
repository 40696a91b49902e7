"""Running the real Scenic for the synthetic-data generators: inputs, the road map, seeding, errors.

Shared by :mod:`.scenic_scenes` (static scenes) and :mod:`.simulate` (simulations).

Scenic parses OpenDRIVE in seconds and caches the result in a ``.snet`` file beside the map: a
pickle, which runs whatever code it names when loaded. So Scenic is only ever given a copy of
the user's ``.xodr`` inside scenegrep's per-user cache (``scenic-maps/<sha256>-scenic<version>/``,
keyed by the map's content), beside which scenegrep itself writes the ``.snet`` (parsed from the
copy, written aside and renamed), and Scenic may read a ``.snet`` from there only: the map
options given to the program turn Scenic's cache writing off. A ``.snet`` beside the user's map
is never read, and one named as the map is refused. When the cache cannot be written, Scenic
reads the user's ``.xodr`` with its ``.snet`` cache off entirely. The program's own
``map_options`` are replaced by these.

Running a Scenic program executes its Python code: ``synth`` is for programs the user trusts.

Scenic is imported inside the functions (about a second), never when this module is imported.
"""

from __future__ import annotations

import contextlib
import hashlib
import random
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
    """The program and the OpenDRIVE map as paths: each must be a regular file, the map a
    ``.xodr`` (a Scenic ``.snet`` is refused); anything else is a :class:`UserError`."""
    from ..readers.common import regular_file
    from ..readers.opendrive import checked_xodr

    return regular_file(program, "a Scenic program"), checked_xodr(map_path)


NO_SNET = {"useCache": False, "writeCache": False}
"""Scenic map options under which ``Network.fromFile`` of an ``.xodr`` never touches a ``.snet``."""


def map_params(map_path: Path) -> dict[str, Any]:
    """The global parameters that give Scenic the map: the cached copy, whose ``.snet`` only
    scenegrep writes, or (when the cache cannot be written) the map itself with Scenic's
    ``.snet`` cache off. A malformed map is a :class:`UserError`."""
    from ..readers.opendrive import checked_xodr, parse_network

    folder = cache_dir() / "scenic-maps" / f"{file_digest(checked_xodr(map_path))[:20]}-scenic{version('scenic')}"
    copy = folder / f"{map_path.stem}.xodr"
    if not (copy.is_file() and copy.with_suffix(".snet").is_file()):
        network = parse_network(map_path)
        try:
            _write_cache(map_path, network, copy)
        except (OSError, UserError):  # the cache cannot be written (the writer's one-line error)
            return {"map": str(map_path), "map_options": dict(NO_SNET)}
    return {"map": str(copy), "map_options": {"useCache": True, "writeCache": False}}


def _write_cache(map_path: Path, network: Any, copy: Path) -> None:
    """Write ``copy`` (the map's bytes) and beside it Scenic's ``.snet`` cache of ``network``
    (parsed from the map's XML), as ``Network.fromFile`` with default map options accepts it
    (digests of the file and of the empty options); each written aside and renamed."""
    from scenic.core.serialization import deterministicHash

    from ..writers.atomic import atomic_path  # the writers package imports pyarrow and shapely

    data = map_path.read_bytes()
    with atomic_path(copy) as tmp:
        tmp.write_bytes(data)
    with atomic_path(copy.with_suffix(".snet")) as tmp:
        network.dumpPickle(tmp, hashlib.blake2b(data).digest(), deterministicHash({}, digest_size=8))


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
