"""``new Class spec, ...``: Scenic 3.1.1's specifier resolution, in 2-D mode, over terms.

Each specifier *specifies* some properties, each at a priority (1 is the
strongest); a property is set by the specifier with the strongest priority for
it, two at the same priority are an error, and class defaults fill what no
specifier sets (``scenic/core/object_types.py: _resolveSpecifiers``). ``on R``
may instead *modify* a position another specifier set: in 2-D this keeps the
position and requires it to lie in R. The priorities and values below are
those of ``scenic/syntax/veneer.py``; the object's heading is
``parentOrientation + yaw``, except that the facing specifiers fix the heading
itself (Scenic computes the yaw that produces it).

Values a specifier computes may read properties of the object being built
(``self``): a scene object's position, heading and size read as its observed
label values (conditioning), its other properties as their defining terms.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from ..scenic import ir
from . import expressions as E
from . import vectors as V
from .context import Context
from .domain import (
    CLASSES,
    DERIVED_PROPERTIES,
    UNMODELLED_PROPERTIES,
    Default,
    default_expression,
    defaulted_properties,
)
from .program import HEADING_FEATURE, Feature, ProgramObject, Requirement
from .regions import (
    Difference,
    Everywhere,
    Field,
    Intersection,
    Region,
    MapField,
    Sector,
    orientation_of,
)
from .terms import RandomPoint, RandomVariable, Term
from .lenient_boxes import eased
from .values import Delayed, Instance, SelfView, Vec, observed_view, type_name
from ..wording import article


@dataclass(frozen=True)
class AbsoluteHeading:
    """A yaw given as the heading it must produce (``facing``): heading = the term itself."""

    heading: Term


@dataclass(eq=False)
class Effect:
    """What one specifier does: properties at priorities, and their values computed from ``self``."""

    name: str
    priorities: dict[str, int]
    compute: Callable[[Any], dict[str, Any]]
    node: ir.Node
    modifies: frozenset[str] = frozenset()
    _values: dict[str, Any] | None = field(default=None, repr=False)

    def values(self, view: Any) -> dict[str, Any]:
        if self._values is None:
            self._values = self.compute(view)
        return self._values


class Builder(SelfView):
    """Resolves the properties of one instance on demand, detecting cycles."""

    def __init__(self, r: Context, instance: Instance, sources: dict[str, Effect | Default]):
        self.r = r
        self.instance = instance
        self.sources = sources
        self.values: dict[str, Any] = {}
        self.pending: set[str] = set()

    def get(self, prop: str) -> Any:
        """``self.prop`` while the instance is being built."""
        if prop in self.instance.observed:
            return self.instance.observed[prop]
        if prop in ("heading", "orientation"):
            return heading_of_instance(self.r, self)
        return self.value(prop)

    def value(self, prop: str) -> Any:
        if prop in self.values:
            return self.values[prop]
        if prop not in self.sources:
            raise self.r.error(f"{self.instance.spec.name} has no property {prop!r}", self.instance.span)
        if prop in self.pending:
            raise self.r.error(f"the property {prop!r} depends on itself", self.instance.span)
        self.pending.add(prop)
        source = self.sources[prop]
        outer, self.r.self_view = self.r.self_view, self
        try:
            result = source.values(self)[prop] if isinstance(source, Effect) else self.r.evaluate_default(source)
            result = result.compute(self) if isinstance(result, Delayed) else result
            if prop == "position" and isinstance(result, (Instance, tuple)):
                result = E.to_vec(self.r, result, self.instance.span)  # a Point stands for its position
        finally:
            self.r.self_view = outer
            self.pending.discard(prop)
        self.values[prop] = result
        return result


def heading_of_instance(r: Context, b: Builder) -> Term:
    """The heading a point or object gets: its absolute facing, else parentOrientation + yaw."""
    yaw = b.value("yaw")
    if isinstance(yaw, AbsoluteHeading):
        return yaw.heading
    parent = E.to_heading(r, b.value("parentOrientation"), b.instance.span)
    return r.f.op("add", parent, E.to_num(r, yaw, b.instance.span, "a yaw"))


# ---------------------------------------------------------------------------- construction
def construct(r: Context, node: ir.New, name: str) -> Instance:
    """Build the instance a ``new`` creates; scene objects join the scene program."""
    spec = CLASSES.get(node.class_name)
    if spec is None:
        known = ", ".join(sorted(CLASSES))
        raise r.error(f"unknown class {node.class_name!r}; a query knows {known}", node)
    instance = Instance(name, spec, node.span)
    if spec.is_object:
        instance.observed = observed_view(r.f, name)
    behaviour = _behaviour_call(r, node)
    effects = [_effect(r, s) for s in node.specifiers if s.property != "behavior"]
    chosen, modifiers = _choose(r, effects)
    sources: dict[str, Effect | Default] = dict(chosen)
    for prop in defaulted_properties(spec.name):
        if prop not in sources:
            sources[prop] = default_expression(spec.name, prop)  # type: ignore[assignment]  # defaulted: not None
    builder = Builder(r, instance, sources)
    for prop in sources:
        instance.defining[prop] = builder.value(prop)
    if "yaw" not in sources:  # a Point has no orientation
        r.instances.append(instance)
        return instance
    instance.defining["heading"] = heading_of_instance(r, builder)
    if isinstance(instance.defining["yaw"], AbsoluteHeading):
        parent = E.to_heading(r, instance.defining["parentOrientation"], node)
        instance.defining["yaw"] = r.f.op("wrap", r.f.op("sub", instance.defining["heading"], parent))
    _check_types(r, instance, node)
    r.instances.append(instance)
    if spec.is_object:
        _add_scene_object(r, instance, chosen, modifiers, node, behaviour)
    elif behaviour is not None:
        raise r.error(f"{article(spec.name)} {spec.name} cannot have a behaviour", behaviour)
    return instance


def _behaviour_call(r: Context, node: ir.New) -> ir.Call | None:
    """The call of the ``with behavior`` specifier, if any (behaviours do not shape the scene)."""
    found = [s for s in node.specifiers if s.property == "behavior"]
    if not found:
        return None
    if len(found) > 1:
        raise r.error("the behaviour is specified twice", found[1])
    value = found[0].operands[0]
    if isinstance(value, ir.Name):
        return ir.Call(value.id, (), span=value.span)
    if not isinstance(value, ir.Call):
        raise r.error("a behaviour must be a behaviour call such as FollowLaneBehavior()", found[0])
    return value


def _choose(r: Context, effects: list[Effect]) -> tuple[dict[str, Effect], list[Effect]]:
    """The specifier setting each property (strongest priority), and the modifying specifiers."""
    chosen: dict[str, Effect] = {}
    seen_names: set[str] = set()
    for effect in effects:
        if effect.name in seen_names and effect.name != "with":
            raise r.error(f"the specifier '{effect.name}' is used twice", effect.node)
        seen_names.add(effect.name)
    modifiers = []
    for effect in sorted(effects, key=lambda e: bool(e.modifies)):
        for prop, priority in effect.priorities.items():
            current = chosen.get(prop)
            if current is None or priority < current.priorities[prop]:
                chosen[prop] = effect
            elif prop in effect.modifies:
                modifiers.append(effect)
            elif priority == current.priorities[prop]:
                raise r.error(
                    f"property {prop!r} is specified twice (by '{current.name}' and '{effect.name}')", effect.node
                )
    return chosen, modifiers


def _check_types(r: Context, instance: Instance, node: ir.New) -> None:
    expected = {"position": Vec, "regionContainedIn": (Region, Term)}
    for prop, kind in expected.items():
        value = instance.defining.get(prop)
        if value is not None and not isinstance(value, kind):
            name = instance.spec.name
            raise r.error(f"the {prop} of {article(name)} {name} cannot be {type_name(value)}", node)


def _add_scene_object(
    r: Context,
    obj: Instance,
    chosen: dict[str, Effect],
    modifiers: list[Effect],
    node: ir.New,
    behaviour: ir.Call | None,
) -> None:
    position: Vec = obj.defining["position"]
    features = [
        Feature(obj.name, "x", position.x, obj.observed["position"].x, node.span),
        Feature(obj.name, "y", position.y, obj.observed["position"].y, node.span),
        Feature(obj.name, HEADING_FEATURE, obj.defining["heading"], obj.observed["heading"], node.span),
    ]
    for size in ("width", "length", "speed", "angularSpeed"):
        effect = chosen.get(size)
        if effect is not None and effect.name == "with":
            value = E.to_num(r, obj.defining[size], effect.node)
            features.append(Feature(obj.name, size, value, obj.observed[size], effect.node.span))
    effect = chosen.get("velocity")
    if effect is not None:
        velocity, observed = E.to_vec(r, obj.defining["velocity"], effect.node), obj.observed["velocity"]
        features.append(Feature(obj.name, "vx", velocity.x, observed.x, effect.node.span))
        features.append(Feature(obj.name, "vy", velocity.y, observed.y, effect.node.span))
    default_size = {}
    for size in ("width", "length"):
        default = r.evaluate_default(default_expression(obj.spec.name, size))  # type: ignore[arg-type]
        default_size[size] = float(default.value)
    r.scene.objects.append(
        ProgramObject(obj.name, obj.spec.name, obj.spec.kinds, tuple(features), default_size, obj.span, behaviour)
    )
    _add_implicit_requirements(r, obj, modifiers, node)


def _add_implicit_requirements(r: Context, obj: Instance, modifiers: list[Effect], node: ir.New) -> None:
    """Scenic's default requirements of a scene object (``Scenario.generateDefaultRequirements``)."""
    box = E.box_terms(obj)
    container = obj.defining.get("regionContainedIn")
    if isinstance(container, Region) and not isinstance(container, Everywhere):
        term = r.f.op("box_in_region", *box, E.EXACT(r), value=container, kind="bool")
        _implicit(r, term, f"{obj.name} lies inside its regionContainedIn", node, container_of=obj.name)
    require_visible = obj.defining.get("requireVisible")
    if obj.name != "ego" and isinstance(require_visible, Term) and require_visible.value is not False:
        ego = r.scope.get("ego")
        if ego is None:
            raise r.error("requireVisible is set but no ego is defined before this object", node)
        visible = E.sees(r, E.visible_region(r, ego, node), obj, node)
        _implicit(
            r,
            r.f.op("or", r.f.op("not", require_visible, kind="bool"), visible, kind="bool"),
            f"{obj.name} is visible from ego",
            node,
        )
    for prop, negate in (("_observingEntity", False), ("_nonObservingEntity", True)):
        if prop in obj.defining:
            entity = obj.defining[prop]
            visible = E.sees(r, E.visible_region(r, entity, node), obj, node)
            word = "not visible" if negate else "visible"
            term = r.f.op("not", visible, kind="bool") if negate else visible
            _implicit(r, term, f"{obj.name} is {word} from {entity.name}", node)
    for effect in modifiers:
        region = effect.values(None)["region"]
        inside = r.f.op("in_region", box[0], box[1], value=region, kind="bool")
        _implicit(r, inside, f"{obj.name}'s position lies in the region of 'on'", effect.node)


def _implicit(
    r: Context, term: Term, description: str, where: ir.Node | ir.Span, container_of: str | None = None
) -> None:
    span = where if isinstance(where, ir.Span) else where.span
    r.scene.requirements.append(
        Requirement(eased(r.f, term), description, span, implicit=True, container_of=container_of)
    )


def add_collision_requirements(r: Context) -> None:
    """No two scene objects' boxes intersect unless one allows collisions."""
    objects = [i for i in r.instances if i.is_object]
    for i, a in enumerate(objects):
        for b in objects[i + 1 :]:
            overlap = r.f.op("boxes_overlap", *E.box_terms(a), *E.box_terms(b), E.EXACT(r), kind="bool")
            allowed = r.f.op("or", a.defining["allowCollisions"], b.defining["allowCollisions"], kind="bool")
            term = r.f.op("or", allowed, r.f.op("not", overlap, kind="bool"), kind="bool")
            if not (term.is_const and term.value is True):
                _implicit(r, term, f"{a.name} and {b.name} do not intersect", a.span)


# ---------------------------------------------------------------------------- specifiers
def _effect(r: Context, node: ir.Specifier) -> Effect:
    operands = [None if o is None else E.evaluate(r, o) for o in node.operands]
    return _SPECIFIERS[node.name](r, node, operands)


def _op_node(node: ir.Specifier, i: int) -> ir.Node:
    return node.operands[i] or node


def _with(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    prop = node.property or ""
    if prop in UNMODELLED_PROPERTIES:
        raise r.error(f"the property {prop!r} is not supported: {UNMODELLED_PROPERTIES[prop]}", node)
    if prop in DERIVED_PROPERTIES:
        raise r.error(f"the property {prop!r} cannot be set: {DERIVED_PROPERTIES[prop]}", node)
    if prop == "heading":
        return _facing(r, node, ops)
    if prop in ("position", "x", "y"):
        value = ops[0]
        return Effect("with", {prop: 1}, lambda view: {prop: E.to_vec(r, value, _op_node(node, 0))}, node)
    return Effect("with", {prop: 1}, lambda view: {prop: ops[0]}, node)


def _at(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    position = E.to_vec(r, ops[0], _op_node(node, 0))
    return Effect("at", {"position": 1}, lambda view: {"position": position}, node)


def random_point(r: Context, region: Region, node: ir.Node, description: str) -> Vec:
    """A point drawn uniformly from ``region`` (cropped to the visible distance around the ego, if set)."""
    if r.visible_distance is not None:
        ego_x, ego_y = r.f.observed("ego", "x"), r.f.observed("ego", "y")
        disc = Sector(ego_x, ego_y, r.f.const(r.visible_distance), r.f.const(0), r.f.const(math.tau))
        region = Intersection((region, disc))
    x, y = r.f.point(RandomPoint(f"{description}: {r.label(node)}", region, node.span))
    return Vec(x, y)


def _own_position(view: Any, point: Vec) -> Vec:
    """The position a specifier's orientation is taken at: the object's (observed for scene
    objects), or the point this specifier is drawing when it is the one setting the position."""
    if not view.instance.is_object and "position" in view.pending:
        return point
    return view.get("position")


def _orientation_value(r: Context, region: Region, position: Vec, node: ir.Node) -> Term:
    """The region's preferred orientation at ``position``; a heading free over the reals where the
    resolver takes the field as unknown and unconstrained (``r.free_fields``: ``--unknown-layers
    permissive`` on a map that does not give it)."""
    field_value = orientation_of(region)
    assert field_value is not None
    if isinstance(field_value, MapField) and field_value.name in r.free_fields:
        name = f"orientation of the region: {r.label(node)}"
        return r.f.var(RandomVariable(name, r.f.const(-math.inf), r.f.const(math.inf), node.span))
    return E.field_at(r, field_value, position)


def _is_oriented_region(region: Region) -> bool:
    return orientation_of(region) is not None


def _in(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    region = E.to_region(r, ops[0], _op_node(node, 0))
    priorities = {"position": 1}
    if node.name == "contained in":
        priorities["regionContainedIn"] = 1
    if _is_oriented_region(region):
        priorities["parentOrientation"] = 3

    def compute(view: Any) -> dict[str, Any]:
        point = random_point(r, region, node, f"point {node.name}")
        values: dict[str, Any] = {"position": point, "regionContainedIn": region}
        if "parentOrientation" in priorities:
            values["parentOrientation"] = _orientation_value(r, region, _own_position(view, point), node)
        return values

    return Effect(node.name, priorities, compute, node)


def _on(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    target = ops[0]
    if isinstance(target, Instance):
        raise r.error("'on <object>' places objects on 3-D surfaces; not supported in 2-D queries", node)
    if isinstance(target, (Vec, tuple)):
        return _at(r, node, ops)
    region = E.to_region(r, target, _op_node(node, 0))
    priorities = {"position": 1}
    if _is_oriented_region(region):
        priorities["parentOrientation"] = 2

    def compute(view: Any) -> dict[str, Any]:
        values: dict[str, Any] = {"region": region}
        if view is not None:
            point = random_point(r, region, node, "point on")
            values["position"] = point
            if "parentOrientation" in priorities:
                values["parentOrientation"] = _orientation_value(r, region, _own_position(view, point), node)
        return values

    return Effect("on", priorities, compute, node, modifies=frozenset({"position"}))


def _ego_of(r: Context, node: ir.Node) -> Instance:
    ego = r.scope.get("ego")
    if ego is None:
        raise r.error("this specifier refers to ego, which is not defined yet", node)
    return ego


def _offset_by(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    ego = _ego_of(r, node)
    offset = E.to_vec(r, ops[0], _op_node(node, 0))
    position = V.offset_locally(r.f, ego.get("position"), ego.get("heading"), offset)
    values = {"position": position, "parentOrientation": ego.get("heading")}
    return Effect("offset by", {"position": 1, "parentOrientation": 3}, lambda view: values, node)


def _offset_along(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    ego = _ego_of(r, node)
    base = ego.get("position")
    direction = ops[0]
    heading = E.field_at(r, direction, base) if isinstance(direction, Field) else E.to_heading(r, direction, node)
    position = V.offset_locally(r.f, base, heading, E.to_vec(r, ops[1], _op_node(node, 1)))
    values = {"position": position, "parentOrientation": ego.get("heading")}
    return Effect("offset along", {"position": 1, "parentOrientation": 3}, lambda view: values, node)


_DIRECTIONS = {
    # name: (axis of self's size, sign along x, sign along y, scalar distance is along x?)
    "left of": ("width", -1, 0, True),
    "right of": ("width", 1, 0, True),
    "ahead of": ("length", 0, 1, False),
    "behind": ("length", 0, -1, False),
}


def _direction(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    """``left of / right of / ahead of / behind X [by D]`` (veneer.directionalSpecHelper)."""
    axis, sx, sy, along_x = _DIRECTIONS[node.name]
    reference, distance = ops
    f = r.f
    if distance is None:
        dx = dy = f.const(0)
    elif isinstance(distance, Term) and distance.kind == "num":
        dx, dy = (distance, f.const(0)) if along_x else (f.const(0), distance)
    else:
        vector = E.to_vec(r, distance, _op_node(node, 1))
        dx, dy = vector.x, vector.y

    def offset(view: Any, ref_size: Term) -> Vec:
        half = f.op("mul", E.to_num(r, view.get(axis), node), f.const(0.5))
        reach = f.op("add", half, f.op("mul", ref_size, f.const(0.5)))
        if sx:
            return Vec(f.op("mul", f.const(sx), f.op("add", reach, dx)), dy)
        return Vec(dx, f.op("mul", f.const(sy), f.op("add", reach, dy)))

    if isinstance(reference, Instance) and reference.spec.name != "Point":
        ref_size = reference.get(axis) if reference.is_object else f.const(0)
        origin, heading = reference.get("position"), reference.get("heading")

        def relative(view: Any) -> dict[str, Any]:
            return {
                "position": V.offset_locally(f, origin, heading, offset(view, ref_size)),
                "parentOrientation": heading,
            }

        return Effect(node.name, {"position": 1, "parentOrientation": 3}, relative, node)
    origin = E.to_vec(r, reference, _op_node(node, 0))

    def absolute(view: Any) -> dict[str, Any]:
        return {"position": V.offset_locally(f, origin, view.get("heading"), offset(view, f.const(0)))}

    return Effect(node.name, {"position": 1}, absolute, node)


def _beyond(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    """``beyond X by D [from Z]``: X + D rotated to face away from Z. Scenic 3.1.1 turns Z into a
    vector before asking whether it is oriented, so the parent orientation is always global (0)."""
    target = E.to_vec(r, ops[0], _op_node(node, 0))
    base = ops[2] if ops[2] is not None else _ego_of(r, node)
    origin = E.to_vec(r, base, _op_node(node, 2))
    offset = ops[1]
    if isinstance(offset, Term) and offset.kind == "num":
        offset = Vec(r.f.const(0), offset)
    offset = E.to_vec(r, offset, _op_node(node, 1))
    direction = V.heading_of(r.f, V.sub(r.f, target, origin))
    values = {"position": V.offset_locally(r.f, target, direction, offset), "parentOrientation": r.f.const(0)}
    return Effect("beyond", {"position": 1, "parentOrientation": 3}, lambda view: values, node)


def _visible(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    base = ops[0] if ops[0] is not None else _ego_of(r, node)
    sector = E.visible_region(r, base, _op_node(node, 0))
    if node.name == "visible":
        return Effect(
            "visible",
            {"position": 3, "_observingEntity": 1},
            lambda view: {"position": random_point(r, sector, node, "visible point"), "_observingEntity": base},
            node,
        )

    def hidden(view: Any) -> dict[str, Any]:
        container = view.value("regionContainedIn")
        region = container if isinstance(container, Region) else Everywhere()
        point = random_point(r, Difference(region, sector), node, "hidden point")
        return {"position": point, "_nonObservingEntity": base}

    return Effect("not visible", {"position": 3, "_nonObservingEntity": 1}, hidden, node)


def _following(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    field_value, base, distance = ops
    if not isinstance(field_value, Field):
        raise r.error(f"expected a vector field, got {type_name(field_value)}", _op_node(node, 0))
    start = E.to_vec(r, base if base is not None else _ego_of(r, node), _op_node(node, 1))
    position = E.follow(r, field_value, start, E.to_num(r, distance, _op_node(node, 2)))

    def compute(view: Any) -> dict[str, Any]:
        orientation = E.field_at(r, field_value, _own_position(view, position))
        return {"position": position, "parentOrientation": orientation}

    return Effect("following", {"position": 1, "parentOrientation": 3}, compute, node)


def _facing(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    heading = ops[0]

    def compute(view: Any) -> dict[str, Any]:
        if isinstance(heading, Field):
            return {"yaw": AbsoluteHeading(E.field_at(r, heading, view.get("position")))}
        value = heading.compute(view) if isinstance(heading, Delayed) else heading
        return {"yaw": AbsoluteHeading(E.to_heading(r, value, _op_node(node, 0)))}

    return Effect("facing", {"yaw": 1}, compute, node)


def _facing_toward(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    target = E.to_vec(r, ops[0], _op_node(node, 0))
    away = node.name == "facing away from"

    def compute(view: Any) -> dict[str, Any]:
        position = view.get("position")
        direction = V.sub(r.f, position, target) if away else V.sub(r.f, target, position)
        return {"yaw": AbsoluteHeading(V.heading_of(r.f, direction))}

    return Effect(node.name, {"yaw": 1}, compute, node)


def _apparently_facing(r: Context, node: ir.Specifier, ops: list[Any]) -> Effect:
    heading = E.to_heading(r, ops[0], _op_node(node, 0))
    base = E.to_vec(r, ops[1] if ops[1] is not None else _ego_of(r, node), _op_node(node, 1))

    def compute(view: Any) -> dict[str, Any]:
        angle = V.heading_of(r.f, V.sub(r.f, view.get("position"), base))
        return {"yaw": r.f.op("add", angle, heading)}

    return Effect("apparently facing", {"yaw": 1}, compute, node)


_SPECIFIERS: dict[str, Callable[[Context, ir.Specifier, list[Any]], Effect]] = {
    "with": _with,
    "at": _at,
    "in": _in,
    "contained in": _in,
    "on": _on,
    "offset by": _offset_by,
    "offset along": _offset_along,
    "left of": _direction,
    "right of": _direction,
    "ahead of": _direction,
    "behind": _direction,
    "beyond": _beyond,
    "visible": _visible,
    "not visible": _visible,
    "following": _following,
    "facing": _facing,
    "facing toward": _facing_toward,
    "facing away from": _facing_toward,
    "apparently facing": _apparently_facing,
}
