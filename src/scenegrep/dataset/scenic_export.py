"""Matches as concrete Scenic programs that re-run the labeled moment in Scenic's Newtonian simulator.

:func:`scenic_program` writes one :class:`~.moments.Moment` as the text of a Scenic 3.1.1
program: every object of the moment is a ``new`` object (the one the query program's ``ego``
corresponds to, else the trace's ego, else the first, is Scenic's ``ego``) of the Scenic class of its category's
canonical kind (:data:`SCENIC_CLASSES`), at its first labeled position and heading, with its
labeled size (a size the labels do not give is left to the class's default), and with the
behaviour ``FollowRecording``, which at every simulation step takes an action putting the
object at its recorded pose for the start of the step and giving it the velocity (m/s) and
angular speed (rad/s) that take it to its recorded pose for the end of the step: the labeled
positions and headings as literals (``repr`` of each float, so the values are the labels' bit
for bit), linear between observations (headings the short way round), held before the first
and after the last (velocity 0 there). Each object starts with the velocity of its first
recorded segment. The Newtonian physics integrates ``position += velocity * dt``, so an object
that is not a car lands on its recording at every step, with its recorded finite-difference
velocity and speed. The simulator drives a car (``isCar``, the driving model's vehicles) along
its heading at its current speed: a car gets its recorded speed (forward or in reverse), moves
along its heading during a step and is put back on its recording at the next, so its
positions stray by at most its side-slip over one step and the error does not accumulate.
``terminate when`` ends the simulation when the
window's duration has passed (rounded to whole steps).

The map: an OpenDRIVE map (a trace's ``map_source`` of format ``opendrive`` naming a file) is
the program's ``param map = localPath(...)`` (relative to the program's folder) with the model
``scenic.simulators.newtonian.driving_model``; Scenic reads no other map format, so such
moments are written without roads (model ``scenic.simulators.newtonian.model``), which the
program's header comment says (and :func:`write_scenic_programs` reports). Every object is
written ``with allowCollisions True, with requireVisible False, with regionContainedIn
everywhere``: labeled boxes overlap and leave the road, and Scenic's default requirements would
reject such scenes. Positions are 2-D (Scenic's driving domain is 2-D: compile with ``--2d`` /
``mode2D=True``); elevations are not written.

Every text from the data (names, ids, categories, paths) enters a program as a Python string
literal (``repr``) or, in comments, JSON-escaped on one line, so no value can inject code.
Writing a program executes nothing.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import re
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import UserError
from ..writers.file_names import file_stem
from ..model.taxonomy import kind_of
from .moments import Moment, ObjectPath, check_output_folder

SCENIC_VERSION = "3.1.1"
"""The Scenic version the programs are written for (the pinned one)."""

DRIVING_MODEL = "scenic.simulators.newtonian.driving_model"
"""The model of programs on an OpenDRIVE map."""

GENERIC_MODEL = "scenic.simulators.newtonian.model"
"""The model of programs without a map Scenic can read (no roads)."""

SCENIC_CLASSES: dict[str, tuple[str, str | None, str | None]] = {
    "car": ("Car", None, ""),
    "truck": ("Truck", "Car", "Car"),
    "bus": ("Bus", "Car", "Car"),
    "trailer": ("Trailer", "Car", "Car"),
    "motorcycle": ("Motorcycle", "Car", "Car"),
    "bicycle": ("Bicycle", "Car", "Car"),
    "pedestrian": ("Pedestrian", None, ""),
    "animal": ("Animal", "Pedestrian", "Pedestrian"),
    "static": ("StaticObject", "NewtonianActor", ""),
    "other": ("OtherObject", "NewtonianActor", ""),
}
"""Canonical kind -> (Scenic class, its base class in the driving model, in the generic model).
A base of None: the model defines the class itself; "": the program defines it on ``Object``."""

_RUNTIME = '''import bisect
import math
from scenic.core.simulators import Action

def recordedPath(text):
    """A recorded path: rows (time, x, y, heading) of floats, one per line of four numbers."""
    return tuple(tuple(float(value) for value in line.split()) for line in text.splitlines() if line.strip())

def recordedPose(path, times, time):
    """The pose (x, y, heading) at `time` s of a recorded path (rows (time, x, y, heading), and
    `times` its times): linear between rows (the heading the short way round), held before the
    first row and after the last."""
    i = bisect.bisect_right(times, time)
    if i == 0 or i == len(path):
        return path[max(i - 1, 0)][1:]
    (t0, x0, y0, h0), (t1, x1, y1, h1) = path[i - 1], path[i]
    a = (time - t0) / (t1 - t0)
    turn = (h1 - h0 + math.pi) % math.tau - math.pi
    return x0 + a * (x1 - x0), y0 + a * (y1 - y0), h0 + a * turn

class SetRecordedMotion(Action):
    """Puts the agent at the pose (x, y, heading) `start` with the velocity (m/s) and angular
    speed (rad/s) that take it to the pose `end` in `dt` s."""
    def __init__(self, start, end, dt):
        self.start, self.end, self.dt = start, end, dt
    def applyTo(self, obj, sim):
        (x0, y0, h0), (x1, y1, h1) = self.start, self.end
        obj.position = Vector(x0, y0)
        obj.heading = h0
        obj.velocity = Vector((x1 - x0) / self.dt, (y1 - y0) / self.dt)
        obj.speed = math.hypot(x1 - x0, y1 - y0) / self.dt
        obj.angularSpeed = ((h1 - h0 + math.pi) % math.tau - math.pi) / self.dt

behavior FollowRecording(path):
    """At every step, the recorded pose for the start of the step and the motion to its end."""
    times = [row[0] for row in path]
    while True:
        dt = simulation().timestep
        now = simulation().currentTime * dt
        take SetRecordedMotion(recordedPose(path, times, now), recordedPose(path, times, now + dt), dt)
'''


@dataclass(frozen=True)
class WrittenProgram:
    """One program written: its file and the reason it has no road map (None: it has the trace's
    OpenDRIVE map)."""

    path: Path
    without_map: str | None


def without_map_counts(written: list[WrittenProgram]) -> dict[str, int]:
    """Reason -> how many of the programs ``written`` have no road map for it, by reason (sorted)."""
    return dict(sorted(Counter(w.without_map for w in written if w.without_map).items()))


def scenic_program(moment: Moment, map_reference: str | None, without_map: str | None = None) -> str:
    """The Scenic program of ``moment`` (module docstring): on the OpenDRIVE map at
    ``map_reference`` (a path relative to the program's folder), or without roads when it is None,
    ``without_map`` saying why. UserError for a moment without objects."""
    if not moment.objects:
        raise UserError(f"match {moment.match} of {moment.trace_name} has no labeled object to export")
    ego = _ego_index(moment)
    objects = [moment.objects[ego]] + [o for i, o in enumerate(moment.objects) if i != ego]
    kinds = [kind_of(o.category) for o in objects]
    lines = _header(moment, map_reference, without_map)
    lines += [_RUNTIME]
    lines += _classes(kinds, map_reference is not None)
    for number, (path, kind) in enumerate(zip(objects, kinds)):
        lines += _object(path, f"obj{number}" if number else "ego", SCENIC_CLASSES[kind][0])
    steps = round(moment.duration / moment.frame_period) if moment.frame_period > 0 else 0
    lines += [
        f"# The moment lasts {moment.duration:.6g} s ({steps} frame periods of {moment.frame_period:.6g} s): "
        "the simulation ends then, at any timestep.",
        f"terminate when simulation().currentTime >= round({_number(moment.duration)} / simulation().timestep)",
        "",
    ]
    return "\n".join(lines)


def write_scenic_programs(moments: Iterable[Moment], folder: str | Path) -> list[WrittenProgram]:
    """Write every moment's program into ``folder`` (created if needed), each as
    ``<trace name>-<match>.scenic`` with the name reduced to letters, digits, ``.``, ``_`` and
    ``-`` (a name two traces share gets the trace id's digest too), written atomically. UserError
    first for a ``folder`` that cannot be one (:func:`scenegrep.dataset.moments.check_output_folder`)."""
    from ..writers.atomic import atomic_path

    check_output_folder(folder, "--scenic")
    folder = Path(folder)
    written: list[WrittenProgram] = []
    owners: dict[str, str] = {}
    for moment in moments:
        stem = file_stem(moment.trace_name)
        if owners.setdefault(stem, moment.trace_id) != moment.trace_id:
            stem = f"{stem}-{hashlib.sha256(moment.trace_id.encode()).hexdigest()[:10]}"
        path = folder / f"{stem}-{moment.match}.scenic"
        reference, reason = _map_reference(moment, folder)
        text = scenic_program(moment, reference, reason)
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
        written.append(WrittenProgram(path, reason))
    return written


def _ego_index(moment: Moment) -> int:
    """The object that is Scenic's ego: the program's ``ego``'s, else the trace's ego, else the first."""
    for i, o in enumerate(moment.objects):
        if o.program_name == "ego":
            return i
    for i, o in enumerate(moment.objects):
        if o.label_id == moment.ego:
            return i
    return 0


def _map_reference(moment: Moment, folder: Path) -> tuple[str | None, str | None]:
    """The moment's OpenDRIVE map as a path relative to ``folder`` (None when it has none Scenic
    reads), and why it has none."""
    source = moment.map_source
    if source is None:
        return None, "the trace has no road map"
    if source.format != "opendrive":
        return None, f"Scenic reads no {_shown(source.format)} map, only OpenDRIVE"
    if not Path(source.path).is_file():
        return None, f"its OpenDRIVE map {_shown(source.path)} is not a file"
    return os.path.relpath(os.path.abspath(source.path), os.path.abspath(folder)), None


def _header(moment: Moment, map_reference: str | None, without_map: str | None) -> list[str]:
    last = moment.start_time + moment.duration
    lines = [
        f"# scenegrep export: match {moment.match} of trace {_quoted(moment.trace_name)} "
        f"(trace id {_quoted(moment.trace_id)}), frames {moment.start_frame}-{moment.end_frame}, "
        f"{moment.start_time:.6g}-{last:.6g} s into the recording.",
        f"# Scenic {SCENIC_VERSION}, 2-D mode (scenic --2d -S FILE; mode2D=True in Python): each object starts at its",
        "# labeled pose and follows its recorded path (positions in the map frame, m; headings in rad,",
        "# 0 along +y, counter-clockwise), linear between frames; elevations are not exported.",
        "# Every step puts each object at its recorded pose and gives it the velocity to its next one (cars",
        "# move along their heading at that speed).",
    ]
    if map_reference is None:
        lines += [
            f"# No road map: {_quoted(without_map or '')[1:-1]}; the objects are placed without roads.",
            f"model {GENERIC_MODEL}",
        ]
    else:
        lines += [f"param map = localPath({map_reference!r})", f"model {DRIVING_MODEL}"]
    return lines + [""]


def _classes(kinds: list[str], driving: bool) -> list[str]:
    """Definitions (bases first) of the Scenic classes the program uses that its model does not
    define, and of the bases among them the program defines."""
    bases = {name: (in_driving if driving else in_generic) for name, in_driving, in_generic in SCENIC_CLASSES.values()}
    needed = {SCENIC_CLASSES[k][0] for k in kinds}
    needed |= {bases[n] for n in needed if bases.get(bases[n] or "") is not None}
    lines = []
    for name, base in bases.items():
        if name in needed and base is not None:
            lines += [f"class {name}({base}):" if base else f"class {name}:", "    pass", ""]
    return lines


def _object(path: ObjectPath, name: str, cls: str) -> list[str]:
    """The object's path literal and its ``new`` statement."""
    constant = f"{name.upper()}_PATH"
    role = "a context object" if path.program_name is None else f"program object {_quoted(path.program_name)}"
    specifiers = [f"at {_number(path.x[0])} @ {_number(path.y[0])}", f"facing {_number(path.heading[0])}"]
    unknown = []
    for prop in ("width", "length", "height"):
        value = getattr(path, prop)
        if math.isfinite(value):
            specifiers.append(f"with {prop} {_number(value)}")
        else:
            unknown.append(prop)
    vx, vy = _first_velocity(path)
    specifiers += [
        f"with velocity {_number(vx)} @ {_number(vy)}",
        f"with speed {_number(math.hypot(vx, vy))}",
        f"with name {path.label_id!r}",
        "with allowCollisions True",
        "with requireVisible False",
        "with regionContainedIn everywhere",
        f"with behavior FollowRecording({constant})",
    ]
    lines = [f"# {name}: {role}, labeled object {_quoted(path.label_id)} ({_quoted(path.category)})"]
    if unknown:
        lines.append(f"# its labels give no {', '.join(unknown)}: Scenic's default for {cls}")
    rows = np.stack([path.times, path.x, path.y, path.heading], axis=1).tolist()
    lines += [
        "# its path: time (s from the window's first frame), x (m), y (m), heading (rad)",
        f'{constant} = recordedPath("""',
        *(f"    {' '.join(_number(v) for v in row)}" for row in rows),
        '""")',
        f"{name} = new {cls} {', '.join(specifiers)}",
        "",
    ]
    return lines


def _first_velocity(path: ObjectPath) -> tuple[float, float]:
    """The velocity (m/s) of the path's first segment; (0, 0) for a path of one observation or one
    first observed after the window's first frame (held until then)."""
    if len(path.times) < 2 or path.times[0] != 0 or not path.times[1] > path.times[0]:
        return 0.0, 0.0
    dt = float(path.times[1] - path.times[0])
    return float(path.x[1] - path.x[0]) / dt, float(path.y[1] - path.y[0]) / dt


def _number(value: float) -> str:
    """A finite float as its exact Python literal."""
    return repr(float(value))


def _shown(text: str) -> str:
    """A format name or path for a message: as it is when plain, else JSON-quoted (one line)."""
    return text if re.fullmatch(r"[A-Za-z0-9._+/-]+", text) else _quoted(text)


def _quoted(text: str) -> str:
    """Text for a comment: JSON-quoted, non-ASCII and control characters escaped (one line)."""
    return json.dumps(str(text), ensure_ascii=True)
