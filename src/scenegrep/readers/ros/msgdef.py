"""ROS 2 message definitions (``.msg`` text as MCAP ``ros2msg`` schemas carry it), parsed.

A ``ros2msg`` schema is the message's own definition followed by the definition of every
type it uses, each after a line of ``=`` and a ``MSG: pkg/Type`` line. Types are named
``pkg/Type`` here (``pkg/msg/Type`` is accepted); a field's type without a package is looked up
in the package of the type that uses it (``Header`` alone is ``std_msgs/Header``). Constants
(``uint8 CAR = 1``) and comments are skipped; default values are ignored.
``builtin_interfaces/Time`` and ``Duration`` are known without a definition.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

PRIMITIVE_SIZES = {
    "bool": 1,
    "byte": 1,
    "char": 1,
    "int8": 1,
    "uint8": 1,
    "int16": 2,
    "uint16": 2,
    "int32": 4,
    "uint32": 4,
    "float32": 4,
    "int64": 8,
    "uint64": 8,
    "float64": 8,
}
"""Bytes of each fixed-size primitive type in CDR (its alignment too)."""

STRINGS = ("string", "wstring")

MAX_SCHEMA_BYTES = 1 << 20
"""The largest schema text read (a message definition with its dependencies is a few kB)."""

_ARRAY = re.compile(r"^(?P<base>[A-Za-z0-9_/]+?)(?:<=(?P<bound>\d+))?(?:\[(?P<size>(?:<=)?\d*)\])?$")


@dataclass(frozen=True)
class Field:
    """A field of a message type: its name, its element type (a primitive, ``string`` or a
    ``pkg/Type``) and its array kind: ``count`` is None for a single value, an int for a fixed
    array of that length, -1 for a sequence (bounded or not)."""

    name: str
    type: str
    count: int | None = None


class DefinitionError(ValueError):
    """A message definition that cannot be parsed or does not define a type it uses."""


BUILTIN = {
    "builtin_interfaces/Time": (Field("sec", "int32"), Field("nanosec", "uint32")),
    "builtin_interfaces/Duration": (Field("sec", "int32"), Field("nanosec", "uint32")),
}


def normalise(name: str, package: str) -> str:
    """``pkg/Type`` for a type reference written in ``package``'s definition (primitives unchanged)."""
    if name in PRIMITIVE_SIZES or name in STRINGS:
        return name
    parts = name.split("/")
    if len(parts) == 1:
        return "std_msgs/Header" if name == "Header" else f"{package}/{name}"
    return f"{parts[0]}/{parts[-1]}"


def _fields(text: str, package: str, where: str) -> tuple[Field, ...]:
    fields = []
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        words = line.split()
        if len(words) < 2:
            raise DefinitionError(f"{where} line {number}: cannot parse {raw.strip()[:60]!r}")
        if "=" in words[1] or (len(words) > 2 and words[2].startswith("=")):
            continue  # a constant
        match = _ARRAY.match(words[0])
        if match is None:
            raise DefinitionError(f"{where} line {number}: bad type {words[0][:60]!r}")
        size = match["size"]
        count = None if size is None else (-1 if size == "" or size.startswith("<=") else int(size))
        base = "string" if match["base"] == "string" else normalise(match["base"], package)
        fields.append(Field(words[1], base, count))
    return tuple(fields)


def parse_schema(name: str, text: str) -> dict[str, tuple[Field, ...]]:
    """Every type a ``ros2msg`` schema defines (its own as ``name``), by ``pkg/Type``;
    :class:`DefinitionError` if a type it uses is not defined."""
    if len(text) > MAX_SCHEMA_BYTES:
        raise DefinitionError(f"schema of {len(text)} characters (at most {MAX_SCHEMA_BYTES})")
    top = normalise(name, "")
    types: dict[str, tuple[Field, ...]] = dict(BUILTIN)
    sections = re.split(r"^={10,}\s*$", text, flags=re.MULTILINE)
    types[top] = _fields(sections[0], top.split("/")[0], top)
    for section in sections[1:]:
        header, _, body = section.strip("\n").partition("\n")
        if not header.startswith("MSG:"):
            raise DefinitionError(f"a schema section starts with {header[:60]!r}, not 'MSG: pkg/Type'")
        type_name = normalise(header[4:].strip(), "")
        types[type_name] = _fields(body, type_name.split("/")[0], type_name)
    for type_name, fields in types.items():
        for f in fields:
            if f.type not in PRIMITIVE_SIZES and f.type not in STRINGS and f.type not in types:
                raise DefinitionError(f"{type_name}.{f.name}: type {f.type} is not defined in the schema")
    return types
