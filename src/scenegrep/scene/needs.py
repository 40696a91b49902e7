"""The map layers a compiled program needs, checked against one road map before matching.

A program part (an object's feature, a requirement, a scenario guard) that reads an unknown layer
(:mod:`scenegrep.model.layers`), in its own text or through a class default such as a
pedestrian's container (sidewalks and crossings), is an error naming the layer and the part,
unless the user chose how to treat unknown layers. An object whose container region is empty on
the map (Town06 has no sidewalks or crossings, so no walkable region) is refused, as Scenic 3.1.1
refuses it ("Container region of ... is empty"). A part that reads the direction of sidewalks or
crossings (``on sidewalk`` orients an object along them) on a map that does not give it (no
centrelines) is an error naming the part, unless the user chose how to treat unknown layers. A
curb direction (``on curb``) has no value to assume: on a map without curbs, unknown or empty, a
program that reads it is refused whatever the choice.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator

from ..errors import UserError, at
from ..scenic import ir
from .geometry import MapGeometry
from .program import SceneProgram
from .regions import Field, MapField, Region
from .terms import Term, value_terms

Part = tuple[Term, str, ir.Span]
"""A program part: its term, how errors name it, and its place in the program."""


def check_layers(program: SceneProgram, geometry: MapGeometry, extra: Iterable[Part] = ()) -> None:
    """Raise :class:`UserError` for the first part that needs an unknown layer without a choice,
    then for the first object whose container region is empty on the map."""
    if geometry.map is None:
        return
    filename = program.program.filename
    for term, name, span in [*program_parts(program), *extra]:
        values = term_values(term)
        if MapField("curb") in values and not geometry.map.curbs:
            held = "does not publish curbs" if "curb" in geometry.map.unknown_layers else "has no curbs"
            raise UserError(
                f"{name} reads the curb's direction, but the road map {geometry.map.name!r} {held}",
                at(filename, span.line, span.column),
            )
        for region in (v for v in values if isinstance(v, Region)):
            layers = geometry.unknown_needed(region)
            if layers and geometry.choice.mode is None:
                where = at(filename, span.line, span.column)
                raise geometry.choice.refuse(layers, name, geometry.map.name, where)
        for field in (v for v in values if isinstance(v, Field)):
            layers = geometry.unoriented(field)
            if layers and geometry.choice.mode is None:
                where = at(filename, span.line, span.column)
                raise geometry.choice.refuse_direction(layers, name, geometry.map.name, where)
    for requirement in program.requirements:
        if requirement.container_of is None:
            continue
        container = geometry.static_geometry(requirement.condition.value)
        if container is not None and container.is_empty:
            obj = program.object(requirement.container_of)
            raise UserError(
                f"the container region (regionContainedIn) of {obj.class_name} {obj.name} is empty on the road map "
                f"{geometry.map.name!r}, so Scenic refuses the scene (Container region of {obj.class_name} is empty)",
                at(filename, requirement.span.line, requirement.span.column),
            )


def program_parts(program: SceneProgram) -> Iterator[Part]:
    """Every feature and requirement of the program, named for errors."""
    for obj in program.objects:
        for feature in obj.features:
            yield feature.term, f"the {feature.name} of {obj.class_name} {obj.name}", feature.span
    for requirement in program.requirements:
        yield requirement.condition, f"the requirement '{requirement.description}'", requirement.span


def free_fields(program: SceneProgram, geometry: MapGeometry) -> frozenset[str]:
    """The map fields the program reads whose values the map does not give, taken as free
    headings (``--unknown-layers permissive``); empty under any other choice."""
    if not geometry.choice.everywhere:
        return frozenset()
    values = (v for term, _, _ in program_parts(program) for v in term_values(term))
    return frozenset(v.name for v in values if isinstance(v, MapField) and geometry.unoriented(v))


def term_regions(term: Term) -> list[Region]:
    """The regions a term reads, through its values and random points."""
    return [v for v in term_values(term) if isinstance(v, Region)]


def term_values(term: Term) -> list[Region | Field]:
    """The regions and fields a term reads, through its values and random points."""
    regions: list[Region | Field] = []
    seen: set[int] = set()
    stack = [term]
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        value = node.value[0].region if node.op == "point" else node.value
        for item in value if isinstance(value, tuple) else (value,):
            if isinstance(item, (Region, Field)):
                regions.append(item)
            stack.extend(value_terms(item))
        stack.extend(node.args)
    return regions
