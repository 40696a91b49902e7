"""CommonRoad scenario XML (versions 2018b and 2020a): obstacle trajectories and the
lanelet road network, both from the one file.

A file's root is ``<commonRoad timeStepSize="0.1" benchmarkID=... commonRoadVersion=...>``.
Obstacles are ``<obstacle id>`` with a ``<role>`` of ``dynamic`` or ``static`` (2018b) or
``<dynamicObstacle id>`` / ``<staticObstacle id>`` (2020a), each with a ``<type>``, a
``<shape>``, an ``<initialState>`` and (dynamic ones) a ``<trajectory>`` of ``<state>``.
A state has an integer ``<time>`` step, a ``<position><point><x>/<y>`` in metres, an
``<orientation>`` (yaw in radians, counter-clockwise from +x) and a ``<velocity>`` (m/s
along the orientation), each quantity as ``<exact>`` or, for uncertain values, an
``<intervalStart>``/``<intervalEnd>`` pair (read as its midpoint; an uncertain position
region is read as its centre).

Trace: frames are every time step from the first to the last obstacle state (frame time =
step × ``timeStepSize`` seconds); one object per obstacle, with the obstacle id as id and
its ``<type>`` as category. A dynamic obstacle is observed at its initial state and every
trajectory state; a static obstacle, which has only an initial state, is observed at that
state in every frame. Headings are converted from yaw to Scenic headings; velocity is split
into vx, vy along the orientation (NaN when the state gives none); sizes come from a
``<rectangle>`` (length, width) or a ``<circle>`` (its diameter for both), NaN for other
shapes; heights are NaN. The ``<planningProblem>`` (the ego vehicle to be planned, which
has no trajectory) is not an object; its ids are kept in the trace attributes.
``<environmentObstacle>`` and ``<phantomObstacle>`` elements carry no states and are ignored.

Map: one lane per ``<lanelet>``: polygon from the left bound and the reversed right bound,
centreline as the mean of the two bounds resampled to the same number of points, topology
from ``<successor>``, ``<predecessor>``, ``<adjacentLeft>``/``<adjacentRight>`` (with
``drivingDir``). A lanelet is an intersection lane when an ``<incoming>`` of an
``<intersection>`` (2020a) names it among its ``successorsRight/Straight/Left``, or when its
centreline midpoint lies in the convex hull of the ends of the intersection's incoming
lanelets (see :func:`_intersection_lanelets`); 2018b files have no intersections. Speed
limits (m/s) come from a lanelet's ``<speedLimit>`` (2018b) or from the lowest maximum-speed
traffic sign (:data:`MAX_SPEED_SIGN_IDS`) the lanelet itself references (2020a; signs are not
carried on to successor lanelets); None otherwise.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from pathlib import Path
from xml.parsers import expat

import numpy as np
import shapely

from ..errors import UserError, at
from ..model import Lane, LaneNeighbour, LabelTrace, MapSource, ObjectTable, RoadMap, StateTable, TraceSource
from ..model.geometry import heading_from_yaw
from ..model.trace import checked_frame_count
from ..model.lane_shapes import resample_polyline
from ..model.lane_topology import derive_intersections, derive_roads
from .common import read_bytes

FORMAT = "commonroad"
ROOT_TAG = "commonRoad"
UNKNOWN_LAYERS = frozenset({"crossing", "sidewalk", "curb", "shoulder"})
"""Layers this reader does not publish: it reads lanelets only (not crosswalk or sidewalk lanelets
as such, nor road boundaries)."""
MAX_SPEED_SIGN_IDS = frozenset({"R2-1", "274"})
"""Traffic sign ids of a maximum speed (value in m/s): USA (MUTCD R2-1) and Germany/Zamunda (StVO 274)."""

_OBSTACLE_ROLES = {"dynamicObstacle": "dynamic", "staticObstacle": "static"}
"""2020a obstacle elements and their role; 2018b ``<obstacle>`` states its role in ``<role>``."""
_INTERSECTION_SUCCESSORS = ("successorsRight", "successorsStraight", "successorsLeft")
_LANE_KINDS = {"bicycleLane": "bike", "busLane": "bus"}
_STATE_FIELDS = 5
"""Columns of an obstacle's state rows: time step, x, y, yaw, speed."""


@dataclass(frozen=True)
class _Document:
    """A parsed scenario file: its path, its bytes (to locate elements in messages) and its root."""

    path: Path
    data: bytes
    root: ET.Element

    def error(self, message: str, element: ET.Element) -> UserError:
        """A :class:`UserError` located at the start tag of ``element``."""
        return UserError(message, at(self.path, *_line_column(self.data, self.root, element)))


def _line_column(data: bytes, root: ET.Element, element: ET.Element) -> tuple[int, int]:
    """1-based line and column of an element's start tag, found by reading the document again
    (only on the error path: ElementTree keeps no positions)."""
    ordinal = next(i for i, e in enumerate(root.iter()) if e is element)
    parser = expat.ParserCreate()
    starts: list[tuple[int, int]] = []
    parser.StartElementHandler = lambda tag, attrs: starts.append(
        (parser.CurrentLineNumber, parser.CurrentColumnNumber + 1)
    )
    parser.Parse(data, True)
    return starts[ordinal]


def _parse(path: str | Path) -> _Document:
    """Read and parse a scenario file; malformed XML or another root is a :class:`UserError`."""
    path = Path(path)
    data = read_bytes(path)
    try:
        root = ET.fromstring(data)
    except ET.ParseError as exc:
        line, column = exc.position
        raise UserError(f"malformed XML: {expat.ErrorString(exc.code)}", at(path, line, column + 1)) from None
    doc = _Document(path, data, root)
    if root.tag != ROOT_TAG:
        raise doc.error(f"not a CommonRoad scenario: the root element is <{root.tag}>, expected <{ROOT_TAG}>", root)
    return doc


# ---------------------------------------------------------------------- element values
def _required(doc: _Document, element: ET.Element, path: str, owner: str) -> ET.Element:
    """The sub-element at ``path``; a :class:`UserError` naming ``owner`` when it is missing."""
    found = element.find(path)
    if found is None:
        raise doc.error(f"{owner} has no <{path}>", element)
    return found


def _float(doc: _Document, element: ET.Element, owner: str) -> float:
    """The text of an element as a number."""
    text = (element.text or "").strip()
    try:
        return float(text)
    except ValueError:
        raise doc.error(f"{owner}: <{element.tag}> is not a number: {text!r}", element) from None


def _attribute_float(doc: _Document, element: ET.Element, name: str) -> float:
    """A required numeric attribute of an element."""
    text = element.get(name)
    try:
        return float(text or "")
    except ValueError:
        raise doc.error(f"<{element.tag}> needs a numeric {name} attribute, found {text!r}", element) from None


def _id(doc: _Document, element: ET.Element) -> str:
    """The ``id`` attribute of an element."""
    value = element.get("id")
    if not value:
        raise doc.error(f"<{element.tag}> has no id", element)
    return value


def _point(doc: _Document, point: ET.Element, owner: str) -> tuple[float, float]:
    """(x, y) in metres of a ``<point>`` (or ``<center>``)."""
    return (
        _float(doc, _required(doc, point, "x", owner), owner),
        _float(doc, _required(doc, point, "y", owner), owner),
    )


def _polyline(doc: _Document, bound: ET.Element, owner: str) -> np.ndarray:
    """The points of a lanelet bound as a (k, 2) array, k >= 2."""
    points = [_point(doc, p, owner) for p in bound.findall("point")]
    if len(points) < 2:
        raise doc.error(f"{owner}: <{bound.tag}> needs at least 2 points, has {len(points)}", bound)
    return np.array(points, dtype=np.float64)


def _unique_ids(doc: _Document, elements: list[ET.Element], what: str) -> list[ET.Element]:
    """The elements, after checking that no two share an id."""
    seen: set[str] = set()
    for element in elements:
        element_id = _id(doc, element)
        if element_id in seen:
            raise doc.error(f"{what} id {element_id} is used twice", element)
        seen.add(element_id)
    return elements


def _refs(element: ET.Element, tag: str) -> tuple[str, ...]:
    """The ``ref`` attributes of the children with a tag, in document order."""
    return tuple(ref for child in element.findall(tag) if (ref := child.get("ref")))


# ---------------------------------------------------------------------- obstacles
@dataclass(frozen=True)
class _Obstacle:
    """One obstacle: id, type, role, shape size (m) and its state rows (:data:`_STATE_FIELDS`)."""

    id: str
    category: str
    static: bool
    length: float
    width: float
    rows: np.ndarray


def _obstacle_elements(root: ET.Element) -> list[ET.Element]:
    """The obstacles of a scenario in document order (2018b and 2020a element names)."""
    return [e for e in root if e.tag == "obstacle" or e.tag in _OBSTACLE_ROLES]


def _role(doc: _Document, element: ET.Element, owner: str) -> str:
    """``dynamic`` or ``static``: from the element name (2020a) or its ``<role>`` (2018b)."""
    if element.tag in _OBSTACLE_ROLES:
        return _OBSTACLE_ROLES[element.tag]
    role = (_required(doc, element, "role", owner).text or "").strip()
    if role not in ("dynamic", "static"):
        raise doc.error(f"{owner}: <role> must be dynamic or static, found {role!r}", element)
    return role


def _size(doc: _Document, element: ET.Element, owner: str) -> tuple[float, float]:
    """(length, width) in metres of an obstacle's shape; NaN for shapes other than rectangle/circle."""
    rectangle = element.find("shape/rectangle")
    if rectangle is not None:
        return (
            _float(doc, _required(doc, rectangle, "length", owner), owner),
            _float(doc, _required(doc, rectangle, "width", owner), owner),
        )
    circle = element.find("shape/circle")
    if circle is not None:
        diameter = 2.0 * _float(doc, _required(doc, circle, "radius", owner), owner)
        return diameter, diameter
    return math.nan, math.nan


def _quantity(doc: _Document, state: ET.Element, tag: str, owner: str) -> float:
    """A state quantity: its ``<exact>`` value, else the midpoint of its interval; NaN when absent."""
    quantity = state.find(tag)
    if quantity is None:
        return math.nan
    exact = quantity.find("exact")
    if exact is not None:
        return _float(doc, exact, owner)
    start, end = quantity.find("intervalStart"), quantity.find("intervalEnd")
    if start is None or end is None:
        raise doc.error(f"{owner}: <{tag}> has neither <exact> nor <intervalStart> and <intervalEnd>", quantity)
    return (_float(doc, start, owner) + _float(doc, end, owner)) / 2.0


def _position(doc: _Document, state: ET.Element, owner: str) -> tuple[float, float]:
    """A state's position: its point, or the centre of an uncertain rectangle/circle region."""
    position = _required(doc, state, "position", owner)
    for path in ("point", "rectangle/center", "circle/center"):
        point = position.find(path)
        if point is not None:
            return _point(doc, point, owner)
    raise doc.error(f"{owner}: <position> has no <point> (nor a rectangle or circle centre)", position)


def _state_row(doc: _Document, state: ET.Element, owner: str) -> tuple[float, ...]:
    """(time step, x, y, yaw, speed) of a state element."""
    step = _quantity(doc, state, "time", owner)
    if math.isnan(step):
        raise doc.error(f"{owner}: a state has no <time>", state)
    if not step.is_integer():
        raise doc.error(f"{owner}: the time step {step} is not an integer", state)
    x, y = _position(doc, state, owner)
    return step, x, y, _quantity(doc, state, "orientation", owner), _quantity(doc, state, "velocity", owner)


def _obstacle(doc: _Document, element: ET.Element) -> _Obstacle:
    """One obstacle element; a static one keeps only its initial state."""
    obstacle_id = _id(doc, element)
    owner = f"<{element.tag}> {obstacle_id}"
    static = _role(doc, element, owner) == "static"
    category = (_required(doc, element, "type", owner).text or "").strip()
    states = [_required(doc, element, "initialState", owner)]
    if not static:
        states += element.findall("trajectory/state")
    rows = np.array([_state_row(doc, s, owner) for s in states], dtype=np.float64).reshape(-1, _STATE_FIELDS)
    if len(np.unique(rows[:, 0])) != len(rows):
        raise doc.error(f"{owner} has several states at the same time step", element)
    return _Obstacle(obstacle_id, category, static, *_size(doc, element, owner), rows)


def _states(obstacles: list[_Obstacle], frame_index: np.ndarray) -> StateTable:
    """The state table over the frames with the given time steps (consecutive): dynamic rows at
    their own step's frame, each static row repeated in every frame."""
    n_frames = len(frame_index)
    rows = np.vstack([o.rows for o in obstacles]) if obstacles else np.zeros((0, _STATE_FIELDS))
    owner = np.repeat(np.arange(len(obstacles)), [len(o.rows) for o in obstacles])
    static = np.array([o.static for o in obstacles], dtype=bool)[owner]
    static_rows = np.flatnonzero(static)
    pick = np.r_[np.flatnonzero(~static), np.repeat(static_rows, n_frames)]
    frame = np.r_[np.searchsorted(frame_index, rows[~static, 0]), np.tile(np.arange(n_frames), len(static_rows))]
    x, y, yaw, speed = rows[pick, 1:].T
    owner = owner[pick]
    return StateTable.build(
        frame=frame,
        object=owner,
        x=x,
        y=y,
        heading=heading_from_yaw(yaw),
        length=np.array([o.length for o in obstacles], dtype=np.float64)[owner],
        width=np.array([o.width for o in obstacles], dtype=np.float64)[owner],
        vx=speed * np.cos(yaw),
        vy=speed * np.sin(yaw),
    )


# ---------------------------------------------------------------------- trace attributes
def _name(doc: _Document) -> str:
    """The scenario's benchmark id (the file name without suffix when the root does not state it)."""
    return doc.root.get("benchmarkID") or doc.path.stem


def _tags(root: ET.Element) -> str:
    """Scenario tags, lower-case, space separated: the 2018b ``tags`` attribute and 2020a ``<scenarioTags>``."""
    tags = (root.get("tags") or "").split() + [t.tag for t in root.findall("scenarioTags/*")]
    return " ".join(tag.lower() for tag in tags)


def _snake_case(name: str) -> str:
    """``geoNameId`` -> ``geo_name_id``."""
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


def _scalar_text(text: str) -> int | float | str:
    """An attribute value: int or float when the text is a number, else the text."""
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            continue
    return text


def _location(root: ET.Element) -> dict[str, int | float | str]:
    """The simple fields of ``<location>`` (2020a), e.g. ``geo_name_id``, ``gps_latitude``."""
    return {
        _snake_case(child.tag): _scalar_text(child.text.strip())
        for child in root.findall("location/*")
        if len(child) == 0 and child.text and child.text.strip()
    }


def _attributes(doc: _Document, name: str) -> dict[str, int | float | str]:
    """Trace attributes: dataset, benchmark id, version, tags, planning problem ids, location fields."""
    root = doc.root
    attributes: dict[str, int | float | str] = {
        "dataset": "commonroad",
        "benchmark_id": name,
        "commonroad_version": root.get("commonRoadVersion", ""),
        "tags": _tags(root),
    }
    problems = [p.get("id", "") for p in root.findall("planningProblem")]
    if problems:
        attributes["planning_problems"] = " ".join(problems)
    return attributes | _location(root)


def read_trace(path: str | Path) -> LabelTrace:
    """Read the obstacles of a CommonRoad scenario file into a trace (see the module docstring)."""
    doc = _parse(path)
    step_size = _attribute_float(doc, doc.root, "timeStepSize")
    if not step_size > 0:
        raise doc.error(f"timeStepSize must be a positive number of seconds, found {step_size}", doc.root)
    name = _name(doc)
    obstacles = [_obstacle(doc, e) for e in _unique_ids(doc, _obstacle_elements(doc.root), "obstacle")]
    steps = np.concatenate([o.rows[:, 0] for o in obstacles]).astype(np.int64) if obstacles else np.zeros(0, np.int64)
    span = checked_frame_count(int(steps.max() - steps.min()) + 1 if len(steps) else 0)
    frame_index = steps.min() + np.arange(span) if len(steps) else steps
    states = _states(obstacles, frame_index)
    objects = ObjectTable.build(
        [o.id for o in obstacles],
        [o.category for o in obstacles],
        [{"role": "static" if o.static else "dynamic"} for o in obstacles],
    )
    return LabelTrace.build(
        name,
        frame_index,
        frame_index * step_size,
        objects,
        states,
        attributes=_attributes(doc, name),
        source=TraceSource(str(path), FORMAT),
        map_source=MapSource(str(path), FORMAT),
    )


# ---------------------------------------------------------------------- map
def _intersection_lanelets(root: ET.Element, lanes: list[Lane]) -> set[str]:
    """Ids of the lanelets inside intersections: those an intersection's incomings lead into
    (right, straight, left), and those whose centreline midpoint lies in the convex hull of
    the centreline ends (at the stop lines) of the intersection's incoming lanelets (a
    junction is often split into several lanelets of which only the first is named)."""
    ends = {lane.id: lane.centreline[-1] for lane in lanes}
    inside: set[str] = set()
    mids = shapely.points([lane.centreline[len(lane.centreline) // 2] for lane in lanes])
    for intersection in root.findall("intersection"):
        incomings = intersection.findall("incoming")
        inside |= {ref for incoming in incomings for tag in _INTERSECTION_SUCCESSORS for ref in _refs(incoming, tag)}
        stop_lines = [ends[ref] for incoming in incomings for ref in _refs(incoming, "incomingLanelet") if ref in ends]
        if len(stop_lines) >= 3:
            hull = shapely.MultiPoint(np.array(stop_lines)).convex_hull
            inside |= {lane.id for lane, mid in zip(lanes, mids) if hull.covers(mid)}
    return inside


def _sign_speed_limits(doc: _Document) -> dict[str, float]:
    """Traffic sign id -> the lowest maximum speed (m/s) it shows, for signs that show one."""
    limits: dict[str, float] = {}
    for sign in doc.root.findall("trafficSign"):
        values = [
            _float(doc, value, f"<trafficSign> {sign.get('id')}")
            for element in sign.findall("trafficSignElement")
            if (element.findtext("trafficSignID") or "").strip() in MAX_SPEED_SIGN_IDS
            for value in element.findall("additionalValue")
        ]
        if values:
            limits[_id(doc, sign)] = min(values)
    return limits


def _speed_limit(doc: _Document, lanelet: ET.Element, owner: str, sign_limits: dict[str, float]) -> float | None:
    """A lanelet's speed limit (m/s): its ``<speedLimit>``, else its lowest speed sign; None when neither."""
    element = lanelet.find("speedLimit")
    if element is not None:
        return _float(doc, element, owner)
    limits = [sign_limits[ref] for ref in _refs(lanelet, "trafficSignRef") if ref in sign_limits]
    return min(limits) if limits else None


def _neighbour(lanelet: ET.Element, tag: str) -> LaneNeighbour | None:
    """The lanelet named by ``<adjacentLeft>``/``<adjacentRight>`` and whether it runs the same way."""
    element = lanelet.find(tag)
    if element is None or not element.get("ref"):
        return None
    return LaneNeighbour(element.get("ref", ""), element.get("drivingDir") == "same")


def _kind(lanelet: ET.Element) -> str:
    """``bike``, ``bus`` or ``vehicle`` from the lanelet's ``<laneletType>`` elements."""
    types = [(t.text or "").strip() for t in lanelet.findall("laneletType")]
    return next((_LANE_KINDS[t] for t in types if t in _LANE_KINDS), "vehicle")


def _lane(doc: _Document, lanelet: ET.Element, sign_limits: dict[str, float]) -> Lane:
    """One lanelet as a lane (not yet marked as an intersection lane)."""
    lane_id = _id(doc, lanelet)
    owner = f"<lanelet> {lane_id}"
    left = _polyline(doc, _required(doc, lanelet, "leftBound", owner), owner)
    right = _polyline(doc, _required(doc, lanelet, "rightBound", owner), owner)
    n = max(len(left), len(right))
    polygon = shapely.make_valid(shapely.Polygon(np.vstack([left, right[::-1]])))
    return Lane(
        lane_id,
        polygon,
        (resample_polyline(left, n) + resample_polyline(right, n)) / 2.0,
        successors=_refs(lanelet, "successor"),
        predecessors=_refs(lanelet, "predecessor"),
        left=_neighbour(lanelet, "adjacentLeft"),
        right=_neighbour(lanelet, "adjacentRight"),
        kind=_kind(lanelet),
        speed_limit=_speed_limit(doc, lanelet, owner, sign_limits),
    )


def read_map(path: str | Path) -> RoadMap:
    """Read the lanelet network of a CommonRoad scenario file (see the module docstring)."""
    doc = _parse(path)
    sign_limits = _sign_speed_limits(doc)
    lanelets = _unique_ids(doc, doc.root.findall("lanelet"), "lanelet")
    lanes = [_lane(doc, lanelet, sign_limits) for lanelet in lanelets]
    inside = _intersection_lanelets(doc.root, lanes)
    lanes = [replace(lane, is_intersection=lane.id in inside) for lane in lanes]
    return RoadMap(
        _name(doc),
        tuple(lanes),
        derive_roads(lanes),
        derive_intersections(lanes),
        source=str(path),
        unknown_layers=UNKNOWN_LAYERS,
    )
