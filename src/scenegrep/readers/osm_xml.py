"""OpenStreetMap XML (``.osm``) read safely into nodes, ways and relations with their tags.

The file is parsed with the standard library's expat parser (the one under ``xml.etree``), which
never fetches external entities; on top of that a document type declaration (DOCTYPE, and with it
any ENTITY declaration: the "billion laughs" expansion) is refused, the file may hold at most
:data:`MAX_BYTES` bytes and :data:`MAX_ELEMENTS` elements, nested at most :data:`MAX_DEPTH` deep
(OSM nests three: ``osm`` > ``way`` > ``nd``). Every element keeps the line it starts on, for the
one-line :class:`~scenegrep.errors.UserError` of a malformed map (``FILE:LINE: message``).
Identifiers are kept as strings (OSM ids are integers, negative in unsaved JOSM edits).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from xml.parsers import expat

from ..errors import UserError, at
from ..wording import article

MAX_BYTES = 512 * 1024 * 1024
"""The largest map file read (a city's Autoware map is tens of megabytes)."""
MAX_ELEMENTS = 20_000_000
"""The most XML elements read."""
MAX_DEPTH = 4
"""The deepest element nesting accepted (OSM uses three levels)."""


@dataclass
class Element:
    """A node, way or relation: its tags, the line it starts on and, for ways, the node ids
    (``refs``), for relations the members as (type, ref, role)."""

    line: int
    attributes: dict[str, str]
    tags: dict[str, str] = field(default_factory=dict)
    refs: list[str] = field(default_factory=list)
    members: list[tuple[str, str, str]] = field(default_factory=list)


@dataclass
class OsmDocument:
    """The primitives of an OSM file by id."""

    nodes: dict[str, Element] = field(default_factory=dict)
    ways: dict[str, Element] = field(default_factory=dict)
    relations: dict[str, Element] = field(default_factory=dict)


_KINDS = {"node": "nodes", "way": "ways", "relation": "relations"}


class _Builder:
    """Expat handlers that fill an :class:`OsmDocument`."""

    def __init__(self, path: Path, parser: expat.XMLParserType):
        self.path, self.parser = path, parser
        self.doc = OsmDocument()
        self.depth = 0
        self.count = 0
        self.current: Element | None = None

    def fail(self, message: str) -> UserError:
        return UserError(message, at(self.path, self.parser.CurrentLineNumber, self.parser.CurrentColumnNumber + 1))

    def required(self, attributes: dict[str, str], name: str, element: str) -> str:
        value = attributes.get(name)
        if value is None:
            raise self.fail(f"<{element}> without {article(name)} {name!r} attribute")
        return value

    def start(self, name: str, attributes: dict[str, str]) -> None:
        self.depth += 1
        self.count += 1
        if self.depth > MAX_DEPTH:
            raise self.fail(f"elements nested deeper than {MAX_DEPTH} levels (not an OSM map)")
        if self.count > MAX_ELEMENTS:
            raise self.fail(f"more than {MAX_ELEMENTS} XML elements")
        if self.depth == 1 and name != "osm":
            raise self.fail(f"the root element is <{name}>, expected <osm>")
        if self.depth == 2:
            self.current = None
            if name in _KINDS:
                element_id = self.required(attributes, "id", name)
                table = getattr(self.doc, _KINDS[name])
                if element_id in table:
                    raise self.fail(f"duplicate {name} id {element_id}")
                self.current = table[element_id] = Element(self.parser.CurrentLineNumber, dict(attributes))
        elif self.depth == 3 and self.current is not None:
            if name == "tag":
                self.current.tags[self.required(attributes, "k", name)] = self.required(attributes, "v", name)
            elif name == "nd":
                self.current.refs.append(self.required(attributes, "ref", name))
            elif name == "member":
                self.current.members.append(
                    (
                        self.required(attributes, "type", name),
                        self.required(attributes, "ref", name),
                        attributes.get("role", ""),
                    )
                )

    def end(self, name: str) -> None:
        self.depth -= 1

    def refuse_declaration(self, *args: object) -> None:
        raise self.fail("DOCTYPE and ENTITY declarations are not allowed in an OSM map")


def read_osm(path: str | Path) -> OsmDocument:
    """The nodes, ways and relations of an OSM XML file; malformed or oversized XML, a document
    type declaration or an element without its id is a one-line :class:`UserError` with the line."""
    path = Path(path)
    try:
        size = path.stat().st_size
        if size > MAX_BYTES:
            raise UserError(f"the map file holds {size} bytes, more than the {MAX_BYTES} read", at(path))
        data = path.read_bytes()
    except OSError as exc:
        raise UserError(f"cannot read: {exc.strerror}", at(path)) from None
    parser = expat.ParserCreate()
    parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)
    builder = _Builder(path, parser)
    parser.StartElementHandler = builder.start
    parser.EndElementHandler = builder.end
    parser.StartDoctypeDeclHandler = builder.refuse_declaration
    parser.EntityDeclHandler = builder.refuse_declaration
    try:
        parser.Parse(data, True)
    except expat.ExpatError as exc:
        raise UserError(
            f"not well-formed XML: {expat.ErrorString(exc.code)}", at(path, exc.lineno, exc.offset + 1)
        ) from None
    return builder.doc
