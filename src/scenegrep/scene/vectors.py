"""Vector algebra on terms, in Scenic's conventions.

Headings are radians, 0 = +y, counter-clockwise. ``rotate(v, h)`` turns a vector
given in an object's local frame (x to its right, y ahead of it) by the object's
heading into the map frame: Scenic's ``Vector.rotatedBy``.
"""

from __future__ import annotations

from .terms import Term, TermFactory
from .values import Vec


def add(f: TermFactory, a: Vec, b: Vec) -> Vec:
    return Vec(f.op("add", a.x, b.x), f.op("add", a.y, b.y))


def sub(f: TermFactory, a: Vec, b: Vec) -> Vec:
    return Vec(f.op("sub", a.x, b.x), f.op("sub", a.y, b.y))


def scale(f: TermFactory, v: Vec, k: Term) -> Vec:
    return Vec(f.op("mul", v.x, k), f.op("mul", v.y, k))


def rotate(f: TermFactory, v: Vec, heading: Term) -> Vec:
    """``v`` rotated counter-clockwise by ``heading``: (x cos h - y sin h, x sin h + y cos h)."""
    cos, sin = f.op("cos", heading), f.op("sin", heading)
    x = f.op("sub", f.op("mul", v.x, cos), f.op("mul", v.y, sin))
    y = f.op("add", f.op("mul", v.x, sin), f.op("mul", v.y, cos))
    return Vec(x, y)


def offset_locally(f: TermFactory, origin: Vec, heading: Term, offset: Vec) -> Vec:
    """The point at ``offset`` in the frame of an oriented point at ``origin`` facing ``heading``."""
    return add(f, origin, rotate(f, offset, heading))


def norm(f: TermFactory, v: Vec) -> Term:
    """Euclidean length sqrt(x² + y²)."""
    return f.op("sqrt", f.op("add", f.op("pow", v.x, value=2), f.op("pow", v.y, value=2)))


def heading_of(f: TermFactory, v: Vec) -> Term:
    """Scenic heading of the direction ``v``: atan2(-x, y)."""
    return f.op("heading_of", v.x, v.y)


def vec_const(f: TermFactory, x: float, y: float) -> Vec:
    return Vec(f.const(x), f.const(y))
