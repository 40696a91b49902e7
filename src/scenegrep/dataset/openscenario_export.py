"""A match as OpenSCENARIO 1.3: one ``.xosc`` file per match, each validated against the
OpenSCENARIO XSD that ``scenariogeneration`` ships before it is written.

A file re-plays one :class:`~scenegrep.dataset.moments.Moment`:

- the road network: ``LogicFile`` names the trace's map when it is OpenDRIVE (its path relative
  to the output file, absolute where no relative path exists); other maps (AV2, nuScenes/ScenarioNet,
  Waymo, CommonRoad) have no OpenDRIVE form, so the file has no road network and says so in its
  ``FileHeader`` description (the caller says it on stderr);
- one entity per object of the moment, named by its program object (``ego``, ``otherCar``) or,
  for a context object, ``obj_<label id>`` (characters other than ``[A-Za-z0-9_.-]`` become
  ``_``; duplicates get ``_2``, ``_3``...), with its label id and dataset category as entity
  properties ``label_id`` and ``category``; its category from :func:`osc_category`; its
  bounding box the median labeled size, centred on the entity's reference point, which is the
  labeled box centre (a dimension the dataset does not give, or gives as non-positive, is the
  category's default of :data:`DEFAULT_SIZE`, and the description lists those objects);
- ``Init``: each entity teleported to its first observation in the window (an object that
  appears later in the window waits there until its trajectory starts);
- one ``FollowTrajectoryAction`` per object observed at two or more frames, in ``position``
  following mode, with a ``Polyline`` whose vertices are the observations (x, y, z in the map
  frame, m; h = yaw from +x, rad) timed in seconds from the window's first frame, and the
  ``Timing`` reference ``absolute`` (vertex times are simulation times), scale 1, offset 0; all
  events start at simulation time 0, and the storyboard stops when the window's time has passed.

Headings convert from Scenic's convention (0 along +y, counter-clockwise) with
:func:`~scenegrep.model.geometry.yaw_from_heading`: the initial pose's yaw is in (-pi, pi], a
trajectory's yaws are unwrapped from it (consecutive vertices differ by less than pi, so a
simulator interpolating them does not spin). ``z`` (and ``h``) are left out of a position where
the dataset gives none; observations without a finite x and y are left out.
"""

from __future__ import annotations

import datetime as dt
import hashlib
import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError
from ..model.geometry import yaw_from_heading
from ..model.taxonomy import kind_of
from ..writers.atomic import atomic_path
from ..writers.file_names import file_stem
from .moments import Moment, ObjectPath, check_output_folder

OSC_MINOR_VERSION = 3
"""The files are OpenSCENARIO 1.3."""

XSD_NAME = "OpenSCENARIO_1_3_1.xsd"
"""The schema every file is validated against, as ``scenariogeneration`` installs it."""

AUTHOR = "scenegrep"

_KINDS = {
    "car": ("vehicle", "car"),
    "truck": ("vehicle", "truck"),
    "bus": ("vehicle", "bus"),
    "trailer": ("vehicle", "trailer"),
    "motorcycle": ("vehicle", "motorbike"),
    "bicycle": ("vehicle", "bicycle"),
    "pedestrian": ("pedestrian", "pedestrian"),
    "animal": ("pedestrian", "animal"),
    "static": ("miscObject", "obstacle"),
    "other": ("miscObject", "none"),
}
_EXACT = {
    "van": ("vehicle", "van"),
    "wheelchair": ("pedestrian", "wheelchair"),
    "railed_vehicle": ("vehicle", "train"),
    "train": ("vehicle", "train"),
}

DEFAULT_SIZE: dict[str, tuple[float, float, float]] = {
    "car": (4.5, 1.8, 1.5),
    "van": (5.0, 2.0, 2.2),
    "truck": (8.0, 2.5, 3.5),
    "bus": (12.0, 2.5, 3.2),
    "trailer": (8.0, 2.5, 3.5),
    "motorbike": (2.2, 0.8, 1.5),
    "bicycle": (1.8, 0.6, 1.7),
    "train": (20.0, 3.0, 4.0),
    "pedestrian": (0.5, 0.5, 1.75),
    "wheelchair": (1.2, 0.7, 1.3),
    "animal": (1.0, 0.4, 0.8),
    "obstacle": (1.0, 1.0, 1.0),
    "none": (1.0, 1.0, 1.0),
}
"""Length, width, height (m) by OpenSCENARIO category, for dimensions a dataset does not give."""

MASS_KG = {"vehicle": 1500.0, "pedestrian": 75.0, "miscObject": 100.0}
"""The (required) mass attribute by entity type: generic, not measured."""

_SAFE = re.compile(r"[^A-Za-z0-9_.-]")
_NOT_XML = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
_MAX_STEM = 120


@dataclass
class ExportSummary:
    """What :func:`write_openscenario` wrote: the files in order, and counts of the limitations
    met (files without a road network, objects with a default dimension, objects observed at a
    single frame, which have a pose but no trajectory)."""

    files: list[Path] = field(default_factory=list)
    without_road_network: int = 0
    default_size: int = 0
    without_trajectory: int = 0


def osc_category(category: str) -> tuple[str, str]:
    """The OpenSCENARIO entity type (``vehicle``, ``pedestrian`` or ``miscObject``) and its
    category (VehicleCategory, PedestrianCategory or MiscObjectCategory value) of a dataset class
    name: by its canonical kind (:mod:`scenegrep.model.taxonomy`), with the few classes
    OpenSCENARIO names exactly (van, wheelchair, train) kept."""
    key = re.sub(r"[\s\-]+", "_", category.strip().lower())
    return _EXACT.get(key) or _KINDS[kind_of(category)]


def xsd_path() -> Path:
    """The OpenSCENARIO 1.3 XSD installed with ``scenariogeneration``."""
    try:
        files = metadata.distribution("scenariogeneration").files or []
    except metadata.PackageNotFoundError:
        files = []
    for file in files:
        if file.name == XSD_NAME:
            return Path(str(file.locate()))
    raise UserError(f"{XSD_NAME} is not installed: reinstall scenariogeneration (pinned in constraints.txt)")


@lru_cache(maxsize=1)
def schema() -> Any:
    """The compiled OpenSCENARIO schema (compiled once per process: about a second)."""
    import xmlschema

    return xmlschema.XMLSchema(str(xsd_path()))


def file_name(moment: Moment) -> str:
    """The file name of a moment: ``<trace id>-match<N>.xosc``, the trace id reduced to
    ``[A-Za-z0-9_.-]`` (no leading dot, at most 120 characters) and, when that changed it, a hash
    of the original appended, so different traces keep different names and none leaves DIR."""
    stem = file_stem(moment.trace_id, _MAX_STEM)
    if stem != moment.trace_id:
        stem = f"{stem}-{hashlib.sha256(moment.trace_id.encode()).hexdigest()[:10]}"
    return f"{stem}-match{moment.match}.xosc"


def write_openscenario(
    moments: Iterable[Moment], out_dir: str | Path, created: dt.datetime | None = None
) -> ExportSummary:
    """Write every moment as ``out_dir/<file_name>`` (atomically), each after it validated
    against the XSD; UserError, with nothing more written, at the first file that does not.
    ``created`` is the FileHeader date (default: now, the same for every file). UserError first
    for an ``out_dir`` that cannot be a folder (:func:`scenegrep.dataset.moments.check_output_folder`)."""
    check_output_folder(out_dir, "--openscenario")
    folder = Path(out_dir)
    created = created or dt.datetime.now().replace(microsecond=0)
    summary = ExportSummary()
    for moment in moments:
        target = folder / file_name(moment)
        if target in summary.files:
            raise UserError(f"{target}: two matches would be written to the same file")
        element, counts = scenario_element(moment, target, created)
        text = _serialise(element)
        errors = list(schema().iter_errors(text.decode("utf-8")))
        if errors:
            reason = " ".join(str(errors[0].reason or errors[0].message).split())
            raise UserError(
                f"{target}: match {moment.match} of {moment.trace_name} does not validate against {XSD_NAME} "
                f"({reason}); not written"
            )
        with atomic_path(target) as tmp:
            tmp.write_bytes(text)
        summary.files.append(target)
        summary.without_road_network += counts["without_road_network"]
        summary.default_size += counts["default_size"]
        summary.without_trajectory += counts["without_trajectory"]
    return summary


def scenario_element(moment: Moment, target: Path, created: dt.datetime) -> tuple[ET.Element, dict[str, int]]:
    """The ``OpenSCENARIO`` element of a moment to be written at ``target``, and its counts of
    limitations (keys as :class:`ExportSummary`'s)."""
    from scenariogeneration import xosc

    names = _entity_names(moment.objects)
    entities = xosc.Entities()
    init = xosc.Init()
    act = xosc.Act("replay", _at_time(xosc, 0.0, "start", xosc.Rule.greaterOrEqual))
    defaulted: list[str] = []
    single: list[str] = []
    duration = 0.0
    for obj, name in zip(moment.objects, names, strict=True):
        entity, was_defaulted = _entity(xosc, obj, name)
        entities.add_scenario_object(name, entity)
        if was_defaulted:
            defaulted.append(name)
        keep = np.isfinite(obj.x) & np.isfinite(obj.y)
        if not keep.any():
            raise UserError(f"{moment.trace_name}: object {obj.label_id} has no finite position in the window")
        poses = _poses(xosc, obj, keep)
        init.add_init_action(name, xosc.TeleportAction(poses[0]))
        times = [float(t) for t in obj.times[keep]]
        duration = max(duration, times[-1])
        if len(poses) < 2:
            single.append(name)
            continue
        trajectory = xosc.Trajectory(f"{name}_path", False).add_shape(xosc.Polyline(times, poses))
        follow = xosc.FollowTrajectoryAction(
            trajectory, xosc.FollowingMode.position, xosc.ReferenceContext.absolute, 1, 0
        )
        event = xosc.Event(f"{name}_follows", xosc.Priority.override)
        event.add_action(f"{name}_follow_path", follow)
        event.add_trigger(_at_time(xosc, 0.0, "start", xosc.Rule.greaterOrEqual))
        group = xosc.ManeuverGroup(f"{name}_group").add_actor(name)
        group.add_maneuver(xosc.Maneuver(f"{name}_replay").add_event(event))
        act.add_maneuver_group(group)
    storyboard = xosc.StoryBoard(init, _at_time(xosc, duration, "stop", xosc.Rule.greaterThan))
    if act.maneuvergroup:
        storyboard.add_story(xosc.Story("replay").add_act(act))
    road, road_note = _road_network(xosc, moment, target)
    notes = [road_note] if road_note else []
    if defaulted:
        notes.append("category's default for a dimension not labeled: " + ", ".join(defaulted))
    if single:
        notes.append("observed at one frame, no trajectory: " + ", ".join(single))
    scenario = xosc.Scenario(
        _xml_text(_description(moment, notes)),
        AUTHOR,
        xosc.ParameterDeclarations(),
        entities,
        storyboard,
        road,
        xosc.Catalog(),
        osc_minor_version=OSC_MINOR_VERSION,
        creation_date=created,
    )
    counts = {"without_road_network": int(road_note is not None), "default_size": len(defaulted)}
    counts["without_trajectory"] = len(single)
    return scenario.get_element(), counts


def _description(moment: Moment, notes: list[str]) -> str:
    text = (
        f"scenegrep match {moment.match} of trace {moment.trace_name}: dataset frames "
        f"{moment.start_frame}..{moment.end_frame}, from {moment.start_time:g} s into the trace; "
        "times are seconds from the window's first frame"
    )
    return "; ".join([text, *notes])


def _road_network(xosc: Any, moment: Moment, target: Path) -> tuple[Any, str | None]:
    """The RoadNetwork element and, when it names no OpenDRIVE file, the limitation to say."""
    source = moment.map_source
    if source is None:
        return xosc.RoadNetwork(), "no road network: the trace has no map"
    if source.format != "opendrive":
        return xosc.RoadNetwork(), (
            f"no road network: the trace's map is {source.format}, not OpenDRIVE (scenegrep converts no maps)"
        )
    path = Path(source.path).resolve()
    try:
        reference = Path(os.path.relpath(path, target.parent.resolve())).as_posix()
    except ValueError:
        reference = path.as_posix()
    return xosc.RoadNetwork(roadfile=_xml_text(reference)), None


def _entity_names(objects: Iterable[ObjectPath]) -> list[str]:
    """Entity names: the program object's name, else ``obj_<label id>``, made safe and unique."""
    names: list[str] = []
    for obj in objects:
        base = _SAFE.sub("_", obj.program_name if obj.program_name else f"obj_{obj.label_id}")
        name, k = base, 1
        while name in names:
            k += 1
            name = f"{base}_{k}"
        names.append(name)
    return names


def _entity(xosc: Any, obj: ObjectPath, name: str) -> tuple[Any, bool]:
    """The entity of an object and whether a dimension of it is a default."""
    kind, category = osc_category(obj.category)
    measured = (obj.length, obj.width, obj.height)
    size = [m if np.isfinite(m) and m > 0 else d for m, d in zip(measured, DEFAULT_SIZE[category], strict=True)]
    length, width, height = (float(v) for v in size)
    box = xosc.BoundingBox(width, length, height, 0, 0, 0)
    if kind == "vehicle":
        wheel = min(0.7, 0.35 * height)
        axle = 0.3 * length
        entity = xosc.Vehicle(
            name,
            getattr(xosc.VehicleCategory, category),
            box,
            xosc.Axle(0.5, wheel, 0.85 * width, axle, wheel / 2),
            xosc.Axle(0.0, wheel, 0.85 * width, -axle, wheel / 2),
            70.0,
            10.0,
            10.0,
            mass=MASS_KG[kind],
        )
    elif kind == "pedestrian":
        entity = xosc.Pedestrian(name, MASS_KG[kind], getattr(xosc.PedestrianCategory, category), box)
    else:
        entity = xosc.MiscObject(name, MASS_KG[kind], getattr(xosc.MiscObjectCategory, category), box)
    entity.add_property("label_id", _xml_text(obj.label_id))
    entity.add_property("category", _xml_text(obj.category))
    return entity, any(s != m for s, m in zip(size, measured, strict=True))


def _poses(xosc: Any, obj: ObjectPath, keep: np.ndarray) -> list[Any]:
    """World positions of the kept observations (yaws unwrapped from the first, in (-pi, pi])."""
    yaw = yaw_from_heading(obj.heading[keep])
    finite = np.isfinite(yaw)
    if finite.any():
        yaw[finite] = np.unwrap(yaw[finite])
    poses = []
    for x, y, z, h in zip(obj.x[keep], obj.y[keep], obj.z[keep], yaw, strict=True):
        poses.append(xosc.WorldPosition(float(x), float(y), _finite(z), _finite(h)))
    return poses


def _finite(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


def _at_time(xosc: Any, seconds: float, point: str, rule: Any) -> Any:
    """A trigger on simulation time (``point`` ``start`` or ``stop``)."""
    condition = xosc.SimulationTimeCondition(float(seconds), rule)
    return xosc.ValueTrigger(f"at_{seconds:g}s", 0, xosc.ConditionEdge.none, condition, point)


def _serialise(element: ET.Element) -> bytes:
    ET.indent(element)
    return ET.tostring(element, encoding="utf-8", xml_declaration=True) + b"\n"


def _xml_text(text: str) -> str:
    """``text`` without the characters XML 1.0 cannot hold."""
    return _NOT_XML.sub("\ufffd", text)
