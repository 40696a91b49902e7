"""Readers: every supported input format turned into the data model.

Each format lives in its own module of this package, loaded only when needed
(so ``scenegrep --help`` and SpRE runs never import Scenic or shapely). A module
offers some of:

- ``read_traces(path) -> Iterator[LabelTrace]`` for files holding several traces, or
  ``read_trace(path) -> LabelTrace`` for files holding one;
- ``read_map(path, key=None) -> RoadMap`` for formats that carry a road map.

:func:`detect_format` names the format of a path; :func:`read_traces`,
:func:`read_trace` and :func:`read_map` dispatch to the module.

A folder of trace files (a dataset written by ``scenegrep synth`` or ``scenegrep label``, say) is
read here, each file by its own format: every file directly in the folder whose format holds label
traces, in name order; other files (a manifest, a README, maps) are skipped, and so are JSON files
that are not scenegrep traces (STREM streams are recognised by weak signs only: give them by
name). Sub-folders are not entered.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path
from types import ModuleType
from collections.abc import Iterator

from typing import TYPE_CHECKING

from ..errors import UserError, at
from ..model import LabelTrace, MapSource
from .common import malformed
from .common import regular_file
from ..wording import article

if TYPE_CHECKING:
    from ..model import RoadMap


@dataclass(frozen=True)
class Format:
    """A supported input format: its name, module (None: read by this package, a folder of trace
    files), and what it holds."""

    name: str
    module: str | None
    description: str
    traces: bool
    map: bool
    many: bool = False
    """Whether one file may hold several traces (outputs then name the trace as well as the file)."""


FORMATS: dict[str, Format] = {
    f.name: f
    for f in (
        Format(
            "strem-json",
            "strem_json",
            "STREM JSON v0.2.0 perception stream (several documents allowed; - for stdin)",
            True,
            False,
        ),
        Format("scenegrep-json", "trace_json", "scenegrep JSON trace (hand-written fixtures)", True, False),
        Format("scenegrep-parquet", "trace_parquet", "scenegrep Parquet trace", True, False),
        Format("scenegrep-map-parquet", "trace_parquet", "scenegrep Parquet road map", False, True),
        Format("av2-sensor", "av2_sensor", "Argoverse 2 sensor log directory (annotations + poses + map)", True, False),
        Format(
            "av2-forecasting", "av2_forecasting", "Argoverse 2 motion-forecasting scenario (parquet + map)", True, False
        ),
        Format("av2-map", "av2_map", "Argoverse 2 vector map JSON", False, True),
        Format(
            "scenarionet", "scenarionet", "ScenarioNet pickle (nuScenes, Waymo, ...), restricted unpickling", True, True
        ),
        Format("waymo-tfrecord", "waymo_tfrecord", "Waymo Open Motion Scenario TFRecord", True, True, many=True),
        Format("commonroad", "commonroad", "CommonRoad 2018b/2020a scenario XML", True, True),
        Format("opendrive", "opendrive", "OpenDRIVE road network (.xodr) through Scenic", False, True),
        Format("lanelet2", "lanelet2", "Lanelet2 map (.osm, as Autoware uses it)", False, True),
        Format(
            "ros-bag",
            "ros.reader",
            "MCAP file or ROS 2 bag directory (Autoware objects, /tf, odometry)",
            True,
            False,
        ),
        Format("trace-folder", None, "folder of trace files (each read in name order)", True, False, many=True),
    )
}

SKIPPED = frozenset({"strem-json"})
"""Formats not collected from a folder of trace files (see the module docstring)."""


def module(format_name: str) -> ModuleType:
    """The reader module of a format."""
    return importlib.import_module(f"{__name__}.{FORMATS[format_name].module}")


def _sniff_json(path: Path) -> str | None:
    with open(path, "rb") as handle:
        head = handle.read(4096)
    if b'"scenegrep"' in head and b'"trace"' in head:
        return "scenegrep-json"
    if b'"lane_segments"' in head or b'"drivable_areas"' in head or b'"pedestrian_crossings"' in head:
        return "av2-map"
    if b'"frames"' in head or b'"version"' in head:
        return "strem-json"
    return None


def sniff_file(path: Path) -> str | None:
    """The format of a file from its name and first bytes, or None."""
    suffix = path.suffix.lower()
    if suffix == ".json":
        return _sniff_json(path)
    if suffix == ".parquet":
        if path.name.startswith("scenario_"):
            return "av2-forecasting"
        kind = module("scenegrep-parquet").kind(path)
        return {"trace": "scenegrep-parquet", "map": "scenegrep-map-parquet"}.get(kind or "")
    if suffix == ".feather" and path.name == "annotations.feather":
        return "av2-sensor"
    simple = {".pkl": "scenarionet", ".pickle": "scenarionet", ".xodr": "opendrive", ".xml": "commonroad"}
    if suffix in simple:
        return simple[suffix]
    if suffix == ".osm":
        return "lanelet2" if module("lanelet2").is_lanelet_map(path) else None
    if suffix == ".tfrecord" or ".tfrecord-" in path.name:
        return "waymo-tfrecord"
    if suffix == ".mcap":
        return "ros-bag"
    return None


def detect_format(path: str | Path) -> str:
    """The format name of a path (``-`` is a STREM stream on stdin); UserError when unknown."""
    if str(path) == "-":
        return "strem-json"
    path = Path(path)
    if path.is_dir():
        if (path / "annotations.feather").is_file() and (path / "city_SE3_egovehicle.feather").is_file():
            return "av2-sensor"
        if any(path.glob("scenario_*.parquet")):
            return "av2-forecasting"
        if (path / "metadata.yaml").is_file() and (any(path.glob("*.mcap")) or any(path.glob("*.db3"))):
            return "ros-bag"
        if trace_files(path):
            return "trace-folder"
        raise UserError("a directory that is neither an Argoverse 2 log or scenario nor holds trace files", at(path))
    file = regular_file(path, "a trace or map file, or a recording directory")
    with malformed(file, file.suffix.lstrip(".").lower() or "input"):  # sniffing reads headers too
        found = sniff_file(file)
    if found is None:
        raise UserError(f"unrecognised input format; supported: {', '.join(FORMATS)}", at(path))
    return found


def trace_files(path: str | Path) -> list[Path]:
    """The files directly in a folder that hold label traces, in name order."""
    found = []
    for child in sorted(Path(path).iterdir()):
        name = sniff_file(child) if child.is_file() else None
        if name is not None and name not in SKIPPED and FORMATS[name].traces:
            found.append(child)
    return found


def _checked(path: str | Path, format_name: str | None, need: str) -> str:
    name = format_name or detect_format(path)
    if name not in FORMATS:
        raise UserError(f"unknown format {name!r}; supported: {', '.join(FORMATS)}", at(path))
    if not getattr(FORMATS[name], need):
        raise UserError(
            f"{article(FORMATS[name].description)} {FORMATS[name].description} holds no "
            f"{'label trace' if need == 'traces' else 'road map'}",
            at(path),
        )
    return name


def read_traces(path: str | Path, format_name: str | None = None) -> Iterator[LabelTrace]:
    """Every trace in a file or recording directory; a malformed input is a :class:`UserError`
    (a path that is neither a directory, nor ``-`` for stdin, must be a regular file)."""
    name = _checked(path, format_name, "traces")
    if name == "trace-folder":
        files = trace_files(path)
        if not files:
            raise UserError("a folder without trace files", at(path))
        for child in files:
            yield from read_traces(child)
        return
    if str(path) != "-" and not Path(path).is_dir():
        regular_file(path, f"a trace file ({name})")
    reader = module(name)
    with malformed(path, name):
        if hasattr(reader, "read_traces"):
            yield from reader.read_traces(path)
        else:
            yield reader.read_trace(path)


def read_trace(path: str | Path, format_name: str | None = None) -> LabelTrace:
    """The one trace of a file or recording directory (UserError if it holds several)."""
    traces = iter(read_traces(path, format_name))
    first = next(traces, None)
    if first is None:
        raise UserError("holds no trace", at(path))
    if next(traces, None) is not None:
        raise UserError("holds several traces; read them with read_traces", at(path))
    return first


@lru_cache(maxsize=16)
def _read_map_cached(path: str, format_name: str, key: str | None) -> RoadMap:
    reader = module(format_name)
    with malformed(path, format_name):
        return reader.read_map(path) if key is None else reader.read_map(path, key)


def read_map(source: MapSource | str | Path, format_name: str | None = None) -> RoadMap:
    """A road map from a :class:`MapSource` or a path (maps are cached per process: a fleet
    of traces usually shares a few city maps). Every map format is a file: a path that is not
    a regular file is a :class:`UserError`."""
    path, key = (source.path, source.key) if isinstance(source, MapSource) else (str(source), None)
    name = _checked(path, source.format if isinstance(source, MapSource) else format_name, "map")
    regular_file(path, f"a road map ({name})")
    return _read_map_cached(path, name, key)


def given_map_source(path: str) -> MapSource:
    """``--map MAP`` as a map source: a file of a map format (UserError otherwise), named by its
    absolute path, so a dataset that ingested it reads it from anywhere."""
    name = _checked(path, None, "map")
    regular_file(path, f"a road map ({name})")
    return MapSource(str(Path(path).resolve()), name)


def map_conflict(name: str, own_map: str) -> UserError:
    """The error of a trace ``name`` that has its own map ``own_map`` and is given a ``--map``."""
    return UserError(
        f"trace {name!r} has its own road map ({Path(own_map).name}) and --map gives another; "
        "--map is for traces without a map: leave it out for this trace"
    )


def with_given_map(trace: LabelTrace, map_path: str | None) -> LabelTrace:
    """``trace`` with the map ``map_path`` (``--map``) when it names none; unchanged without
    ``map_path``. One rule in ``ingest``, ``label`` and the query commands: a trace that names its
    own map and is given a ``map_path`` is a UserError for that trace (:func:`map_conflict`),
    never a silent choice of one of the two maps; which map is meant is the user's to say."""
    if map_path is None:
        return trace
    if trace.map_source is not None:
        raise map_conflict(trace.name, trace.map_source.path)
    return replace(trace, map_source=given_map_source(map_path))
