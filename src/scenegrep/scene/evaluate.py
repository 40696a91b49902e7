"""Vectorised evaluation of terms over rows of partial correspondences.

A row is one candidate: a frame and, for each program object matched so far,
the label state it corresponds to. :class:`Evaluator` computes terms for all
rows at once with numpy: :meth:`~Evaluator.value` for terms that depend only
on label values, :meth:`~Evaluator.affine` for terms linear in the group's
unknown random variables (``const + Σ coef·u``). Where a term has several
possible values for one row — a finite ``Options`` choice, or the road
direction inside an intersection — the evaluator *expands*: the row is copied
once per value, and ``origin`` maps the copies back to the original rows, so
the caller can accept a row when any copy is feasible.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from ..errors import UserError, at
from ..model import LabelTrace
from ..model.geometry import heading_of_vector, normalize_angle
from ..model.kinematics import ESTIMATED_VELOCITY, finite_difference_acceleration
from ..model.trace import EGO_SIZE_UNKNOWN
from .follow import walk_end
from .geometry import MapGeometry
from .program import TRACE, ProgramObject
from .regions import Region
from .shapes import boxes_overlap
from .terms import Term


class NotAffine(Exception):
    """A term is not linear in the unknowns (the caller falls back to a general solver)."""


DYNAMIC_COLUMNS = {
    "vx": "vx",
    "vy": "vy",
    "speed": "speed",
    "angularSpeed": "angular_speed",
    "ax": "ax",
    "ay": "ay",
}
"""Dynamic features (m/s, rad/s, m/s²) -> their :class:`Labels` column; NaN there means the trace lacks them."""
_FEATURE_NAMES = {"vx": "velocity", "vy": "velocity", "ax": "acceleration", "ay": "acceleration"}
"""The Scenic property a feature is part of, for messages."""


@dataclass
class Labels:
    """Label state columns of one trace (indexed by state row) and its trace attributes.

    ``vx``, ``vy`` and ``speed`` are in m/s, ``angular_speed`` in rad/s; NaN where the data has no
    value. ``ax``, ``ay`` (m/s², map frame) are derived, never read: the finite differences of
    ``vx``, ``vy`` along each track of ``trace``
    (:func:`~scenegrep.model.kinematics.finite_difference_acceleration`), so unknown where the
    velocities are. ``trace`` (when known) names the places of unknown values in errors.
    """

    x: np.ndarray
    y: np.ndarray
    heading: np.ndarray
    length: np.ndarray
    width: np.ndarray
    attributes: dict = field(default_factory=dict)
    vx: np.ndarray | None = None
    vy: np.ndarray | None = None
    speed: np.ndarray | None = None
    angular_speed: np.ndarray | None = None
    trace: LabelTrace | None = None

    def dynamic(self, obj: str, feature: str, states: np.ndarray) -> np.ndarray:
        """Dynamic feature ``feature`` of program object ``obj`` at label state rows ``states``; a
        :class:`UserError` naming the feature, the trace, the object and the frame if one is unknown."""
        column = getattr(self, DYNAMIC_COLUMNS[feature])
        values = np.full(len(states), np.nan) if column is None else column[states]
        unknown = np.flatnonzero(np.isnan(values))
        if len(unknown):
            raise self._unknown(obj, feature, int(states[unknown[0]]))
        return values

    @cached_property
    def _acceleration(self) -> tuple[np.ndarray, np.ndarray] | None:
        if self.vx is None or self.vy is None or self.trace is None:
            return None
        states = replace(self.trace.states, vx=self.vx, vy=self.vy)
        return finite_difference_acceleration(states, self.trace.frame_time)

    @property
    def ax(self) -> np.ndarray | None:
        """Acceleration along x (m/s²) per state row; None when the trace has no velocities."""
        return None if self._acceleration is None else self._acceleration[0]

    @property
    def ay(self) -> np.ndarray | None:
        """Acceleration along y (m/s²) per state row; None when the trace has no velocities."""
        return None if self._acceleration is None else self._acceleration[1]

    def size(self, obj: str, feature: str, states: np.ndarray, default: float) -> np.ndarray:
        """Length or width (``feature``, m) of program object ``obj`` at label state rows ``states``,
        the class's ``default`` where the trace gives none; a :class:`UserError` instead where the
        row is the trace's ego and the trace says its ego's size is unknown
        (:data:`~scenegrep.model.trace.EGO_SIZE_UNKNOWN`: a bag's ego)."""
        column = getattr(self, feature)[states]
        missing = np.isnan(column)
        reason = self.attributes.get(EGO_SIZE_UNKNOWN)
        trace = self.trace
        if reason is not None and trace is not None and trace.ego is not None and missing.any():
            ego = np.flatnonzero(missing & (trace.states.object[states] == trace.object_index(trace.ego)))
            if len(ego):
                frame = int(trace.frame_index[trace.states.frame[states[ego[0]]]])
                where = None if trace.source is None else at(trace.source.path)
                message = (
                    f"{obj}.{feature} is unknown: trace {trace.name!r} has no size for its ego {trace.ego!r} "
                    f"(at frame {frame}); {reason}"
                )
                raise UserError(message, where)
        return np.where(missing, default, column)

    def _unknown(self, obj: str, feature: str, state: int) -> UserError:
        if self.trace is None:
            name = _FEATURE_NAMES.get(feature, feature)
            return UserError(f"{obj}.{name} is unknown: the trace has no {name}")
        trace = self.trace
        label = trace.objects.id[trace.states.object[state]]
        frame = int(trace.frame_index[trace.states.frame[state]])
        where = None if trace.source is None else at(trace.source.path)
        name = _FEATURE_NAMES.get(feature, feature)
        message = f"{obj}.{name} is unknown: trace {trace.name!r} has no {name} for object {label!r} at frame {frame}"
        estimated = trace.attributes.get(ESTIMATED_VELOCITY)
        if estimated is not None and name != "angularSpeed":
            message += f" (the data records none, and its {estimated} give no estimate without a frame within 1 s)"
        elif name == "acceleration":
            message += " (accelerations are differences of labeled velocities of the track's neighbouring frames)"
        return UserError(message, where)


@dataclass
class Rows:
    """Partial correspondences: ``frame[i]`` and ``state[obj][i]``, the label state row matched to
    program object ``obj`` in row i."""

    frame: np.ndarray
    state: dict[str, np.ndarray]

    def __len__(self) -> int:
        return len(self.frame)

    def take(self, idx: np.ndarray) -> Rows:
        return Rows(self.frame[idx], {k: v[idx] for k, v in self.state.items()})


@dataclass
class Affine:
    """``const + Σ coefs[u] * u`` over rows; ``coefs`` maps unknown leaves to coefficient arrays."""

    const: np.ndarray
    coefs: dict[Term, np.ndarray]

    def take(self, idx: np.ndarray) -> Affine:
        return Affine(self.const[idx], {u: c[idx] for u, c in self.coefs.items()})

    def scaled(self, k: np.ndarray) -> Affine:
        return Affine(self.const * k, {u: c * k for u, c in self.coefs.items()})

    def plus(self, other: Affine, sign: float = 1.0) -> Affine:
        coefs = dict(self.coefs)
        for u, c in other.coefs.items():
            coefs[u] = coefs[u] + sign * c if u in coefs else sign * c
        return Affine(self.const + sign * other.const, coefs)


_UNARY = {
    "neg": np.negative,
    "abs": np.abs,
    "sin": np.sin,
    "cos": np.cos,
    "wrap": normalize_angle,
}
_BINARY = {
    "add": np.add,
    "sub": np.subtract,
    "mul": np.multiply,
    "min": np.minimum,
    "max": np.maximum,
    "lt": np.less,
    "le": np.less_equal,
    "eq": np.equal,
    "ne": np.not_equal,
    "and": np.logical_and,
    "or": np.logical_or,
}


class Evaluator:
    """Evaluates terms over rows, expanding rows for multi-valued terms; see the module docstring."""

    def __init__(
        self,
        rows: Rows,
        labels: Labels,
        objects: dict[str, ProgramObject],
        geometry: MapGeometry,
        unknowns: frozenset[Term] = frozenset(),
        position_tolerance: float = 0.0,
    ):
        self.rows = rows
        self.labels = labels
        self.objects = objects
        self.geometry = geometry
        self.unknowns = unknowns
        self.position_tolerance = position_tolerance
        self.origin = np.arange(len(rows))
        self.memo: dict[Term, np.ndarray] = {}
        self.affine_memo: dict[Term, Affine] = {}
        self.notes: Counter[str] = Counter()
        """Verdicts of the row solvers (``solver:status``), for reports."""

    @property
    def size(self) -> int:
        return len(self.origin)

    # ---------------------------------------------------------------- expansion
    def expand(self, idx: np.ndarray) -> None:
        """Keep (and copy) current rows ``idx``: every computed array follows."""
        self.origin = self.origin[idx]
        self.memo = {t: a[idx] for t, a in self.memo.items()}
        self.affine_memo = {t: a.take(idx) for t, a in self.affine_memo.items()}

    def expand_choice(self, choice: Term) -> None:
        """Copy every row once per alternative of a finite choice, binding the choice's value."""
        size = choice.value.size
        n = self.size
        self.expand(np.repeat(np.arange(n), size))
        self.memo[choice] = np.tile(np.arange(size, dtype=float), n)

    def depends_on_unknowns(self, term: Term) -> bool:
        return bool(self.unknowns) and (term in self.unknowns or not self.unknowns.isdisjoint(term.leaves()))

    # ---------------------------------------------------------------- known values
    def value(self, term: Term) -> np.ndarray:
        """The term's value in every current row (it must not depend on the unknowns)."""
        found = self.memo.get(term)
        if found is not None:
            return found
        if term in self.unknowns:
            raise NotAffine(f"{term!r} is unknown")
        result = self._compute(term)
        if term not in self.memo:  # an expansion may already have stored it
            self.memo[term] = result
        return self.memo[term]

    def _args(self, term: Term) -> list[np.ndarray]:
        for arg in term.args:
            self.value(arg)
        for part in _value_terms(term.value):
            self.value(part)
        return [self.memo[arg] for arg in term.args]

    def _compute(self, term: Term) -> np.ndarray:
        op = term.op
        n = self.size
        if op == "const":
            return np.full(n, term.value, dtype=object if term.kind in ("str", "none") else None)
        if op == "observed":
            return self._observed(*term.value)
        if op in _UNARY:
            return _UNARY[op](self._args(term)[0])
        if op in _BINARY:
            a, b = self._args(term)
            return _BINARY[op](a, b)
        if op == "div":
            a, b = self._args(term)
            with np.errstate(divide="ignore", invalid="ignore"):
                return a / b
        if op == "pow":
            return self._args(term)[0] ** term.value
        if op == "sqrt":
            with np.errstate(invalid="ignore"):
                return np.sqrt(self._args(term)[0])
        if op == "heading_of":
            dx, dy = self._args(term)
            return heading_of_vector(dx, dy)
        if op == "not":
            return ~self._args(term)[0]
        if op == "ite":
            test, body, orelse = self._args(term)
            return np.where(test, body, orelse)
        if op == "select":
            args = self._args(term)
            return np.choose(args[0].astype(np.intp), args[1:])
        return self._geometry(term)

    def _observed(self, obj: str, feature: str) -> np.ndarray:
        if obj == TRACE:
            return np.full(self.size, self.labels.attributes[feature], dtype=object)
        states = self.rows.state[obj][self.origin]
        if feature in DYNAMIC_COLUMNS:
            return self.labels.dynamic(obj, feature, states)
        if feature in ("width", "length"):
            return self.labels.size(obj, feature, states, self.objects[obj].default_size[feature])
        return getattr(self.labels, feature)[states]

    def _geometry(self, term: Term) -> np.ndarray:
        op = term.op
        if op == "field":
            return self._field(term)
        args = self._args(term)
        value = self.value
        region: Region = term.value
        if op == "in_region":
            return self.geometry.contains_points(region, args[0], args[1], value)
        if op == "region_distance":
            return self.geometry.distances(region, args[0], args[1])
        if op == "box_in_region":
            x, y, h, length, width, ease = args
            shrink = 2 * self.position_tolerance * ease
            return self.geometry.contains_boxes(region, x, y, h, _size(length - shrink), _size(width - shrink), value)
        if op == "box_visible":
            x, y, h, length, width, ease = args
            grow = 2 * self.position_tolerance * ease
            return self.geometry.boxes_meet_oriented(region, x, y, h, _size(length + grow), _size(width + grow), value)
        if op == "boxes_overlap":
            grow = 2 * self.position_tolerance * args[10]
            a = (*args[:3], _size(args[3] + grow), _size(args[4] + grow))
            b = (*args[5:8], _size(args[8] + grow), _size(args[9] + grow))
            return boxes_overlap(a, b)
        if op == "follow":  # one coordinate (term.value[1]: 0 = x, 1 = y) of the walk's end
            x, y, distance = self._args(term)
            field, axis = term.value
            return walk_end(self.geometry, field, x, y, distance, self.value)[axis]
        raise ValueError(f"cannot evaluate {op}")

    def _field(self, term: Term) -> np.ndarray:
        x, y = self._args(term)
        rows, headings = self.geometry.field_values(term.value, x, y, self.value)
        if len(rows) != self.size or np.any(rows != np.arange(self.size)):
            self.expand(rows)
        return headings

    # ---------------------------------------------------------------- affine forms
    def affine(self, term: Term) -> Affine:
        """The term as an affine form in the unknowns; raises :class:`NotAffine` otherwise."""
        found = self.affine_memo.get(term)
        if found is not None:
            return found
        if term in self.unknowns:
            result = Affine(np.zeros(self.size), {term: np.ones(self.size)})
        elif not self.depends_on_unknowns(term):
            result = Affine(self.value(term), {})
        else:
            result = self._affine_op(term)
        self.affine_memo[term] = result
        return self.affine_memo[term]

    def _affine_args(self, term: Term) -> list[Affine]:
        for arg in term.args:
            self.affine(arg)
        return [self.affine_memo[arg] for arg in term.args]

    def _affine_op(self, term: Term) -> Affine:
        op = term.op
        if op in ("add", "sub"):
            a, b = self._affine_args(term)
            return a.plus(b, 1.0 if op == "add" else -1.0)
        if op == "neg":
            return self._affine_args(term)[0].scaled(np.full(self.size, -1.0))
        if op == "mul":
            a, b = self._affine_args(term)
            if a.coefs and b.coefs:
                raise NotAffine("product of unknowns")
            return b.scaled(a.const) if not a.coefs else a.scaled(b.const)
        if op == "div":
            a, b = self._affine_args(term)
            if b.coefs:
                raise NotAffine("division by an unknown")
            return a.scaled(1.0 / b.const)
        if op == "select":
            parts = self._affine_args(term)[1:]
            index = self.value(term.args[0]).astype(np.intp)
            result = Affine(np.zeros(self.size), {})
            for k, part in enumerate(parts):
                result = result.plus(part.scaled((index == k).astype(float)))
            return result
        raise NotAffine(f"{op} of an unknown")


def _size(size: np.ndarray) -> np.ndarray:
    """A box side after the tolerance adjustment, never negative."""
    return np.maximum(size, 0.0)


def _value_terms(value: object) -> list[Term]:
    terms = getattr(value, "terms", None)
    if callable(terms):
        return list(terms())
    if isinstance(value, tuple):
        return [t for item in value for t in _value_terms(item)]
    return []
