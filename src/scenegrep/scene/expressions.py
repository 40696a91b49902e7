"""Expressions of a scene program -> values: arithmetic, Scenic operators, distributions.

Each Scenic operator follows Scenic 3.1.1 in 2-D mode (``scenic/syntax/veneer.py``);
objects used as vectors stand for their positions, as headings for their
headings. Each occurrence of a distribution (``Range(4, 10)``) is one random
variable, shared by every use of the name it is bound to, as in Scenic.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..scenic import ir
from . import vectors as V
from .context import Context
from .domain import CLASSES
from .regions import Difference, Everywhere, Field, Intersection, LaneAt, Region, Sector, Union
from .terms import FiniteChoice, RandomVariable, Term
from .values import Delayed, Instance, Namespace, SelfView, Vec, type_name

DEG = math.pi / 180
MAX_CHOICES = 32
"""Most values of one ``Options``/``Uniform``/``DiscreteRange`` (numpy's ``choose`` takes at most 64 arrays)."""

_BINARY = {"+": "add", "-": "sub", "*": "mul", "/": "div"}
_COMPARE = {"<": ("lt", False), "<=": ("le", False), ">": ("lt", True), ">=": ("le", True), "==": ("eq", False)}


def evaluate(r: Context, node: ir.Node) -> Any:
    """The value of an IR expression."""
    handler = _HANDLERS.get(type(node))
    if handler is None:
        raise r.error(f"{type(node).__name__} expressions are not supported", node)
    return handler(r, node)


# ---------------------------------------------------------------------------- coercions
def to_num(r: Context, value: Any, node: ir.Node, what: str = "a number") -> Term:
    if isinstance(value, Term) and value.kind == "num":
        return value
    raise r.error(f"expected {what}, got {type_name(value)}", node)


def to_bool(r: Context, value: Any, node: ir.Node) -> Term:
    if isinstance(value, Term) and value.kind == "bool":
        return value
    raise r.error(f"expected a condition, got {type_name(value)}", node)


def to_vec(r: Context, value: Any, node: ir.Node) -> Vec:
    """A vector: a Vec, an object's or point's position, or a 2-sequence of numbers."""
    if isinstance(value, Vec):
        return value
    if isinstance(value, Instance):
        return value.get("position")
    if isinstance(value, tuple) and len(value) == 2:
        return Vec(to_num(r, value[0], node), to_num(r, value[1], node))
    raise r.error(f"expected a vector, got {type_name(value)}", node)


def to_heading(r: Context, value: Any, node: ir.Node) -> Term:
    """A heading: a number (radians) or an oriented point's or object's heading."""
    if isinstance(value, Instance) and value.spec.name != "Point":
        return value.get("heading")
    return to_num(r, value, node, "a heading")


def to_region(r: Context, value: Any, node: ir.Node) -> Region:
    if isinstance(value, Region):
        return value
    raise r.error(f"expected a region, got {type_name(value)}", node)


def is_oriented(value: Any) -> bool:
    """Whether a value is an OrientedPoint or an Object (has a heading)."""
    return isinstance(value, Instance) and value.spec.name != "Point"


def visible_region(r: Context, value: Any, node: ir.Node) -> Sector:
    """The 2-D visible region of a point (a disc) or oriented point/object (a sector)."""
    if not isinstance(value, Instance):
        raise r.error(f"expected a point or object, got {type_name(value)}", node)
    position = value.get("position")
    distance = value.get("visibleDistance")
    if is_oriented(value):
        return Sector(position.x, position.y, distance, value.get("heading"), value.get("viewAngle"))
    return Sector(position.x, position.y, distance, r.f.const(0), r.f.const(math.tau))


# ---------------------------------------------------------------------------- Python expressions
def _constant(r: Context, node: ir.Constant) -> Any:
    if isinstance(node.value, int) and not isinstance(node.value, bool):
        return r.f.const(float(node.value))
    return r.f.const(node.value)


def _name(r: Context, node: ir.Name) -> Any:
    return r.lookup(node)


def _sequence(r: Context, node: ir.Sequence) -> Any:
    items = tuple(evaluate(r, item) for item in node.items)
    if len(items) == 2 and all(isinstance(i, Term) and i.kind == "num" for i in items):
        return Vec(items[0], items[1])
    return items


def _mapping(r: Context, node: ir.Mapping) -> Any:
    return {k: evaluate(r, v) for k, v in zip(node.keys, node.values)}


def _unary(r: Context, node: ir.Unary) -> Any:
    value = evaluate(r, node.operand)
    if node.op == "not":
        return r.f.op("not", to_bool(r, value, node.operand), kind="bool")
    if isinstance(value, Vec):
        return value if node.op == "+" else Vec(r.f.op("neg", value.x), r.f.op("neg", value.y))
    number = to_num(r, value, node.operand)
    return number if node.op == "+" else r.f.op("neg", number)


def _binary(r: Context, node: ir.Binary) -> Any:
    left, right = evaluate(r, node.left), evaluate(r, node.right)
    if isinstance(left, Delayed) or isinstance(right, Delayed):
        return _delayed_binary(r, node, left, right)
    if node.op == "**":
        exponent = to_num(r, right, node.right)
        if not (exponent.is_const and float(exponent.value).is_integer() and exponent.value >= 0):
            raise r.error("only constant whole-number exponents are supported", node.right)
        return r.f.op("pow", to_num(r, left, node.left), value=int(exponent.value))
    if node.op not in _BINARY:
        raise r.error(f"the operator {node.op} is not supported", node)
    if isinstance(left, Vec) or isinstance(right, Vec):
        return _vector_arithmetic(r, node, left, right)
    return r.f.op(_BINARY[node.op], to_num(r, left, node.left), to_num(r, right, node.right))


def _vector_arithmetic(r: Context, node: ir.Binary, left: Any, right: Any) -> Vec:
    if node.op in "+-":
        a, b = to_vec(r, left, node.left), to_vec(r, right, node.right)
        return V.add(r.f, a, b) if node.op == "+" else V.sub(r.f, a, b)
    if node.op == "*":
        if isinstance(left, Vec):
            return V.scale(r.f, left, to_num(r, right, node.right))
        return V.scale(r.f, to_vec(r, right, node.right), to_num(r, left, node.left))
    if node.op == "/" and isinstance(left, Vec):
        return V.scale(r.f, left, r.f.op("div", r.f.const(1), to_num(r, right, node.right)))
    raise r.error(f"cannot apply {node.op} to {type_name(left)} and {type_name(right)}", node)


def _delayed_binary(r: Context, node: ir.Binary, left: Any, right: Any) -> Delayed:
    def compute(view: Any) -> Any:
        a = left.compute(view) if isinstance(left, Delayed) else left
        b = right.compute(view) if isinstance(right, Delayed) else right
        return r.f.op(_BINARY[node.op], to_num(r, a, node.left), to_num(r, b, node.right))

    if node.op not in ("+", "-"):
        raise r.error(f"the operator {node.op} cannot combine a field with a heading", node)
    return Delayed(compute, "a heading relative to a field")


def _compare(r: Context, node: ir.Compare) -> Term:
    left, right = evaluate(r, node.left), evaluate(r, node.right)
    if node.op in ("in", "not in"):
        inside = _contains(r, node, left, right)
        return inside if node.op == "in" else r.f.op("not", inside, kind="bool")
    if node.op in ("is", "is not"):
        raise r.error("'is' comparisons are not supported; use ==", node)
    if node.op in ("==", "!=") and isinstance(left, Term) and isinstance(right, Term) and left.kind == right.kind:
        equal = r.f.op("eq", left, right, kind="bool")
        return equal if node.op == "==" else r.f.op("not", equal, kind="bool")
    op, swap = _COMPARE.get(node.op, ("ne", False)) if node.op != "!=" else ("ne", False)
    a, b = to_num(r, left, node.left), to_num(r, right, node.right)
    return r.f.op(op, *((b, a) if swap else (a, b)), kind="bool")


def _contains(r: Context, node: ir.Compare, thing: Any, region: Any) -> Term:
    """``X in R``: an object's box is inside R (Scenic's containsObject), a point lies in R."""
    area = to_region(r, region, node.right)
    if isinstance(thing, Instance) and thing.is_object:
        return r.f.op("box_in_region", *box_terms(thing), EXACT(r), value=area, kind="bool")
    point = to_vec(r, thing, node.left)
    return r.f.op("in_region", point.x, point.y, value=area, kind="bool")


def EXACT(r: Context) -> Term:  # noqa: N802 - a constant
    """The 'ease' argument of a box predicate before :func:`.lenient_boxes.eased` sets it (0: exact)."""
    return r.f.const(0)


def box_terms(obj: Instance) -> tuple[Term, Term, Term, Term, Term]:
    """(x, y, heading, length, width) of a scene object, as seen from outside it."""
    position = obj.get("position")
    return position.x, position.y, obj.get("heading"), obj.get("length"), obj.get("width")


def _bool_op(r: Context, node: ir.BoolOp) -> Term:
    terms = [to_bool(r, evaluate(r, operand), operand) for operand in node.operands]
    result = terms[0]
    for term in terms[1:]:
        result = r.f.op(node.op, result, term, kind="bool")
    return result


def _conditional(r: Context, node: ir.Conditional) -> Term:
    test = to_bool(r, evaluate(r, node.test), node.test)
    body, orelse = evaluate(r, node.body), evaluate(r, node.orelse)
    if not (isinstance(body, Term) and isinstance(orelse, Term) and body.kind == orelse.kind):
        raise r.error("both branches of a conditional expression must be numbers (or both booleans)", node)
    return r.f.op("ite", test, body, orelse, kind=body.kind)


def _attribute(r: Context, node: ir.Attribute) -> Any:
    value = evaluate(r, node.value)
    if isinstance(value, Namespace):
        if node.attr not in value.attributes:
            raise r.error(f"{value.name} has no attribute {node.attr!r}", node)
        return value.attributes[node.attr]
    if isinstance(value, Vec) and node.attr in ("x", "y"):
        return value.x if node.attr == "x" else value.y
    if isinstance(value, Instance):
        return _property(r, node, value)
    if isinstance(value, SelfView):
        return value.get(node.attr)
    raise r.error(f"{type_name(value)} has no attribute {node.attr!r}", node)


def _property(r: Context, node: ir.Attribute, obj: Instance) -> Any:
    attr = node.attr
    if attr == "lane":
        position = obj.get("position")
        return LaneAt(position.x, position.y)
    if attr == "visibleRegion":
        return visible_region(r, obj, node.value)
    if attr in obj.observed or attr in obj.defining:
        return obj.get(attr)
    raise r.error(f"{obj.name} has no property {attr!r} that a query can use", node)


# ---------------------------------------------------------------------------- calls and distributions
def _call(r: Context, node: ir.Call) -> Any:
    handler = _CALLS.get(node.function)
    if handler is None:
        raise r.error(f"unknown or unsupported function {node.function!r}", node)
    if node.keywords:
        raise r.error(f"{node.function} takes no keyword arguments here", node)
    return handler(r, node, [evaluate(r, a) for a in node.args])


def _arity(r: Context, node: ir.Call, args: list[Any], *counts: int) -> None:
    if len(args) not in counts:
        expected = " or ".join(str(c) for c in counts)
        raise r.error(f"{node.function} takes {expected} arguments, got {len(args)}", node)


def _variable(r: Context, node: ir.Call, low: Term, high: Term) -> Term:
    return r.f.var(RandomVariable(r.label(node), low, high, node.span))


def _range(r: Context, node: ir.Call, args: list[Any]) -> Term:
    _arity(r, node, args, 2)
    low, high = (to_num(r, a, n) for a, n in zip(args, node.args))
    if low.is_const and high.is_const and low.value > high.value:
        raise r.error("Range(low, high) needs low <= high", node)
    return _variable(r, node, low, high)


def _normal(r: Context, node: ir.Call, args: list[Any]) -> Term:
    _arity(r, node, args, 2)
    for a, n in zip(args, node.args):
        to_num(r, a, n)
    return _variable(r, node, r.f.const(-math.inf), r.f.const(math.inf))


def _truncated_normal(r: Context, node: ir.Call, args: list[Any]) -> Term:
    _arity(r, node, args, 4)
    low, high = (to_num(r, a, n) for a, n in zip(args[2:], node.args[2:]))
    return _variable(r, node, low, high)


def _options(r: Context, node: ir.Call, args: list[Any]) -> Any:
    _arity(r, node, args, 1)
    values = args[0]
    if isinstance(values, dict):
        weights = [to_num(r, w, node) for w in values.values()]
        if not all(w.is_const and w.value >= 0 for w in weights):
            raise r.error("Options weights must be non-negative constants", node)
        values = tuple(v for v, w in zip(values, weights) if w.value > 0)
        values = tuple(evaluate(r, k) for k in values)
    if isinstance(values, Vec):  # a two-number list
        values = (values.x, values.y)
    if not isinstance(values, tuple) or not values:
        raise r.error("Options takes a non-empty list or a dict of weights", node)
    return choose(r, node, values)


def _uniform(r: Context, node: ir.Call, args: list[Any]) -> Any:
    if not args:
        raise r.error("Uniform takes at least one value", node)
    return choose(r, node, tuple(args))


def _discrete_range(r: Context, node: ir.Call, args: list[Any]) -> Any:
    _arity(r, node, args, 2)
    low, high = (to_num(r, a, n) for a, n in zip(args, node.args))
    if not (low.is_const and high.is_const and float(low.value).is_integer() and float(high.value).is_integer()):
        raise r.error("DiscreteRange needs constant whole-number bounds", node)
    if high.value - low.value >= MAX_CHOICES:
        raise r.error(f"a random choice may have at most {MAX_CHOICES} values", node)
    return choose(r, node, tuple(r.f.const(v) for v in range(int(low.value), int(high.value) + 1)))


def choose(r: Context, node: ir.Node, values: tuple[Any, ...]) -> Any:
    """A random choice among values: numbers, strings, booleans, vectors or regions (one shared index)."""
    if len(values) == 1:
        return values[0]
    if len(values) > MAX_CHOICES:
        raise r.error(f"a random choice may have at most {MAX_CHOICES} values", node)
    if all(isinstance(v, Region) for v in values):
        return Union(values)
    index = r.f.choice(FiniteChoice(r.label(node), len(values), node.span))
    if all(isinstance(v, Term) for v in values) and len({v.kind for v in values}) == 1:
        return r.f.select(index, values)
    if all(isinstance(v, (Vec, tuple, Instance)) for v in values):
        points = [to_vec(r, v, node) for v in values]
        return Vec(r.f.select(index, tuple(p.x for p in points)), r.f.select(index, tuple(p.y for p in points)))
    raise r.error("Options/Uniform over values of different or unsupported types", node)


def _minmax(r: Context, node: ir.Call, args: list[Any]) -> Term:
    if len(args) < 2:
        raise r.error(f"{node.function} takes at least two numbers", node)
    terms = [to_num(r, a, n) for a, n in zip(args, node.args)]
    result = terms[0]
    for term in terms[1:]:
        result = r.f.op(node.function, result, term)
    return result


def _abs(r: Context, node: ir.Call, args: list[Any]) -> Term:
    _arity(r, node, args, 1)
    return r.f.op("abs", to_num(r, args[0], node.args[0]))


def _relative_speed(r: Context, node: ir.Call, args: list[Any]) -> Term:
    """``RelativeSpeed(X[, Y])``, scenegrep's extension (Scenic 3.1.1 has no such operator):
    |X.velocity - Y.velocity| in m/s, Y the ego when omitted, X and Y scene objects."""
    _arity(r, node, args, 1, 2)
    if len(args) == 1 and "ego" not in r.scope:
        raise r.error("RelativeSpeed(X) refers to ego, which is not defined yet", node)
    objects = [*args, r.scope["ego"]] if len(args) == 1 else args
    for obj, arg in zip(objects, [*node.args, node]):
        if not (isinstance(obj, Instance) and obj.is_object):
            raise r.error(f"RelativeSpeed needs scene objects, got {type_name(obj)}", arg)
    return V.norm(r.f, V.sub(r.f, objects[0].get("velocity"), objects[1].get("velocity")))


def _local_path(r: Context, node: ir.Call, args: list[Any]) -> Term:
    _arity(r, node, args, 1)
    if not (isinstance(args[0], Term) and args[0].kind == "str"):
        raise r.error("localPath takes a file name", node)
    return r.f.const(r.local_path(args[0].value))


_CALLS: dict[str, Callable[[Context, ir.Call, list[Any]], Any]] = {
    "Range": _range,
    "Normal": _normal,
    "TruncatedNormal": _truncated_normal,
    "Options": _options,
    "Discrete": _options,
    "Uniform": _uniform,
    "DiscreteRange": _discrete_range,
    "min": _minmax,
    "max": _minmax,
    "abs": _abs,
    "localPath": _local_path,
    "RelativeSpeed": _relative_speed,
}


# ---------------------------------------------------------------------------- Scenic operators
def _operator(r: Context, node: ir.Operator) -> Any:
    operands = [None if o is None else evaluate(r, o) for o in node.operands]
    return _OPERATORS[node.name](r, node, operands)


def _operand(node: ir.Operator, i: int) -> ir.Node:
    return node.operands[i] or node


def _deg(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    return r.f.op("mul", to_num(r, ops[0], _operand(node, 0)), r.f.const(DEG))


def _vector(r: Context, node: ir.Operator, ops: list[Any]) -> Vec:
    return Vec(to_num(r, ops[0], _operand(node, 0)), to_num(r, ops[1], _operand(node, 1)))


def field_at(r: Context, field: Field, point: Vec) -> Term:
    """The heading of a field at a point."""
    return r.f.op("field", point.x, point.y, value=field)


def _field_at(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    if not isinstance(ops[0], Field):
        raise r.error(f"expected a vector field, got {type_name(ops[0])}", _operand(node, 0))
    return field_at(r, ops[0], to_vec(r, ops[1], _operand(node, 1)))


def _relative_to(r: Context, node: ir.Operator, ops: list[Any]) -> Any:
    """``X relative to Y``: Scenic's RelativeTo for fields, oriented points, headings and vectors."""
    x, y = ops
    if isinstance(x, Field) or isinstance(y, Field):
        return _field_relative(r, node, x, y)
    if is_oriented(x) or is_oriented(y):
        point, other = (x, y) if is_oriented(x) else (y, x)
        if isinstance(other, Term) and other.kind == "num":
            return r.f.op("add", point.get("heading"), other)
        if is_oriented(other):
            raise r.error("'X relative to Y' with both X and Y oriented points", node)
        offset = to_vec(r, other, node)
        return V.offset_locally(r.f, point.get("position"), point.get("heading"), offset)
    if isinstance(x, Term) and isinstance(y, Term):
        return r.f.op("add", to_num(r, x, _operand(node, 0)), to_num(r, y, _operand(node, 1)))
    return V.add(r.f, to_vec(r, x, _operand(node, 0)), to_vec(r, y, _operand(node, 1)))


def _field_relative(r: Context, node: ir.Operator, x: Any, y: Any) -> Delayed:
    """A heading relative to a field: the field at the position of the object being built, plus the heading."""

    def value(part: Any, view: Any, i: int) -> Term:
        if isinstance(part, Field):
            return field_at(r, part, view.get("position"))
        return to_num(r, part, _operand(node, i), "a heading")

    return Delayed(lambda view: r.f.op("add", value(x, view, 0), value(y, view, 1)), "a heading relative to a field")


def _offset_along(r: Context, node: ir.Operator, ops: list[Any]) -> Vec:
    base = to_vec(r, ops[0], _operand(node, 0))
    direction = field_at(r, ops[1], base) if isinstance(ops[1], Field) else to_heading(r, ops[1], _operand(node, 1))
    return V.offset_locally(r.f, base, direction, to_vec(r, ops[2], _operand(node, 2)))


def _from_ego(r: Context, value: Any) -> Any:
    return r.scope["ego"] if value is None else value


def _ego_required(r: Context, node: ir.Operator, ops: list[Any]) -> None:
    if any(o is None for o in ops) and "ego" not in r.scope:
        raise r.error("this operator refers to ego, which is not defined yet", node)


def _relative_position(r: Context, node: ir.Operator, ops: list[Any]) -> Vec:
    _ego_required(r, node, ops)
    target = to_vec(r, ops[0], _operand(node, 0))
    return V.sub(r.f, target, to_vec(r, _from_ego(r, ops[1]), _operand(node, 1)))


def _relative_heading(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    _ego_required(r, node, ops)
    target = to_heading(r, ops[0], _operand(node, 0))
    return r.f.op("wrap", r.f.op("sub", target, to_heading(r, _from_ego(r, ops[1]), _operand(node, 1))))


def _apparent_heading(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    _ego_required(r, node, ops)
    if not is_oriented(ops[0]):
        raise r.error("'apparent heading of X' needs X an oriented point or object", _operand(node, 0))
    position = ops[0].get("position")
    base = to_vec(r, _from_ego(r, ops[1]), _operand(node, 1))
    direction = V.heading_of(r.f, V.sub(r.f, position, base))
    return r.f.op("wrap", r.f.op("sub", ops[0].get("heading"), direction))


def _distance(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    _ego_required(r, node, ops)
    a, b = ops[0], _from_ego(r, ops[1])
    if isinstance(a, Region) or isinstance(b, Region):
        region, point = (a, b) if isinstance(a, Region) else (b, a)
        p = to_vec(r, point, node)
        return r.f.op("region_distance", p.x, p.y, value=region)
    return V.norm(r.f, V.sub(r.f, to_vec(r, a, _operand(node, 0)), to_vec(r, b, _operand(node, 1))))


def _distance_past(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    _ego_required(r, node, ops)
    base = _from_ego(r, ops[1])
    if not is_oriented(base):
        raise r.error("'distance past X of Y' needs Y an oriented point or object", node)
    # Scenic's OrientedPoint.distancePast: (own position - X) in the own frame, ahead component
    offset = V.sub(r.f, base.get("position"), to_vec(r, ops[0], _operand(node, 0)))
    return V.rotate(r.f, offset, r.f.op("neg", base.get("heading"))).y


def _angle(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    _ego_required(r, node, ops)
    source = to_vec(r, _from_ego(r, ops[0]), _operand(node, 0))
    target = to_vec(r, _from_ego(r, ops[1]), _operand(node, 1))
    return V.heading_of(r.f, V.sub(r.f, target, source))


def _follow(r: Context, node: ir.Operator, ops: list[Any]) -> Instance:
    if not isinstance(ops[0], Field):
        raise r.error(f"expected a vector field, got {type_name(ops[0])}", _operand(node, 0))
    position = follow(r, ops[0], to_vec(r, ops[1], _operand(node, 1)), to_num(r, ops[2], _operand(node, 2)))
    return oriented_point(r, node, position, field_at(r, ops[0], position))


def follow(r: Context, field: Field, start: Vec, distance: Term) -> Vec:
    """Scenic's ``F.followFrom(start, distance)``: forward Euler along the field (see :mod:`.geometry`)."""
    return Vec(
        r.f.op("follow", start.x, start.y, distance, value=(field, 0)),
        r.f.op("follow", start.x, start.y, distance, value=(field, 1)),
    )


def _visible(r: Context, node: ir.Operator, ops: list[Any]) -> Region:
    region = to_region(r, ops[0], _operand(node, 0))
    if node.name in ("visible", "not visible") and "ego" not in r.scope:
        raise r.error("'visible R' refers to ego, which is not defined yet", node)
    base = r.scope["ego"] if node.name in ("visible", "not visible") else ops[1]
    sector = visible_region(r, base, _operand(node, 1) if len(node.operands) > 1 else node)
    if node.name.startswith("not"):
        return Difference(region, sector)
    return Intersection((region, sector))


def _can_see(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    sector = visible_region(r, ops[0], _operand(node, 0))
    return sees(r, sector, ops[1], _operand(node, 1))


def sees(r: Context, sector: Sector, target: Any, node: ir.Node) -> Term:
    """Scenic 2-D visibility without occlusion: an object's box meets the sector, a point lies in it."""
    if isinstance(target, Instance) and target.is_object:
        return r.f.op("box_visible", *box_terms(target), EXACT(r), value=sector, kind="bool")
    point = to_vec(r, target, node)
    return r.f.op("in_region", point.x, point.y, value=sector, kind="bool")


def _intersects(r: Context, node: ir.Operator, ops: list[Any]) -> Term:
    a, b = ops
    if isinstance(a, Instance) and isinstance(b, Instance) and a.is_object and b.is_object:
        return r.f.op("boxes_overlap", *box_terms(a), *box_terms(b), EXACT(r), kind="bool")
    obj, region = (a, b) if isinstance(a, Instance) else (b, a)
    if not (isinstance(obj, Instance) and obj.is_object and isinstance(region, Region)):
        raise r.error("'X intersects Y' needs two objects, or an object and a region", node)
    inside = r.f.op("box_in_region", *box_terms(obj), EXACT(r), value=_complement(region), kind="bool")
    return r.f.op("not", inside, kind="bool")


def _complement(region: Region) -> Region:
    return Difference(Everywhere(), region)


def oriented_point(r: Context, node: ir.Node, position: Vec, heading: Term) -> Instance:
    """An OrientedPoint value made by an operator (``follow``, ``front of``)."""
    spec = CLASSES["OrientedPoint"]
    point = Instance(f"OrientedPoint@{node.span.line}", spec, node.span)
    point.defining.update(
        position=position,
        heading=heading,
        parentOrientation=heading,
        yaw=r.f.const(0),
        visibleDistance=r.f.const(50),
        viewAngle=r.f.const(math.tau),
        width=r.f.const(0),
        length=r.f.const(0),
    )
    return point


_SIDES = {
    "front of": (0, 1),
    "back of": (0, -1),
    "left of": (-1, 0),
    "right of": (1, 0),
    "front left of": (-1, 1),
    "front right of": (1, 1),
    "back left of": (-1, -1),
    "back right of": (1, -1),
}


def _position_of(r: Context, node: ir.Operator, ops: list[Any]) -> Instance:
    """``front of O`` and friends: the oriented point at that side of the object's box."""
    obj = ops[0]
    if not (isinstance(obj, Instance) and obj.is_object):
        raise r.error(f"'{node.name} O' needs an object, got {type_name(obj)}", _operand(node, 0))
    sx, sy = _SIDES[node.name]
    half = Vec(r.f.op("mul", obj.get("width"), r.f.const(sx / 2)), r.f.op("mul", obj.get("length"), r.f.const(sy / 2)))
    position = V.offset_locally(r.f, obj.get("position"), obj.get("heading"), half)
    return oriented_point(r, node, position, obj.get("heading"))


_OPERATORS: dict[str, Callable[[Context, ir.Operator, list[Any]], Any]] = {
    "deg": _deg,
    "vector": _vector,
    "field at": _field_at,
    "relative to": _relative_to,
    "offset along": _offset_along,
    "relative position": _relative_position,
    "relative heading": _relative_heading,
    "apparent heading": _apparent_heading,
    "distance": _distance,
    "distance past": _distance_past,
    "angle": _angle,
    "follow": _follow,
    "visible": _visible,
    "not visible": _visible,
    "visible from": _visible,
    "not visible from": _visible,
    "can see": _can_see,
    "intersects": _intersects,
    **{name: _position_of for name in _SIDES},
}

_HANDLERS: dict[type, Callable[[Context, Any], Any]] = {
    ir.Constant: _constant,
    ir.Name: _name,
    ir.Sequence: _sequence,
    ir.Mapping: _mapping,
    ir.Unary: _unary,
    ir.Binary: _binary,
    ir.Compare: _compare,
    ir.BoolOp: _bool_op,
    ir.Conditional: _conditional,
    ir.Attribute: _attribute,
    ir.Call: _call,
    ir.Operator: _operator,
}
