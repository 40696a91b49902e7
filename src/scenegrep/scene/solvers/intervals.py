"""Interval arithmetic for a δ-complete branch-and-prune solver (dReal-style).

Contract:

* An :class:`Interval` is an immutable *closed* interval ``[lo, hi]`` of reals with
  ``lo <= hi``; a bound may be infinite (``[-inf, 5]`` is the half-line up to 5), but the
  interval always holds at least one real, so ``[inf, inf]`` and NaN bounds are rejected.
* Every operation is *sound*: its result contains the exact real result for every choice
  of reals in its operands. Each computed (rounded) bound is widened outward by one ulp
  with :func:`math.nextafter`; bounds known exactly (negation, clipping, ``0``, ``±1``,
  ``±inf``) are not widened. The ``math`` functions used are accurate to within one ulp.
* Results are tight up to those ulps, except where documented (division by an interval
  holding zero gives the whole real line; :func:`rotate` loses the correlation between
  ``cos`` and ``sin``).
* Angles are in radians; :func:`atan2` follows the mathematical convention (angle of the
  point ``(x, y)``) and returns an *unwrapped* interval across the branch cut.

The module is pure Python on floats: it runs once per box in the solver's loop.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from math import inf

PI_LO = math.pi  # the float below the real π
PI_HI = math.nextafter(math.pi, inf)  # the float above it
TWO_PI = 2.0 * math.pi  # = 2 * PI_LO exactly, below the real 2π
TWO_PI_HI = math.nextafter(TWO_PI, inf)  # above it
HALF_PI = 0.5 * math.pi
_MAX = sys.float_info.max
_TURNS_EXACT = 2.0**50  # angle distances of larger values are not resolved (keeps turn counts exact floats)
_SLACK = 2.0**-40  # relative margin when testing whether an extremum of sin / cos may lie in an interval


def _lower(x: float) -> float:
    """The float just below ``x`` (outward rounding of a lower bound)."""
    return math.nextafter(x, -inf)


def _upper(x: float) -> float:
    """The float just above ``x`` (outward rounding of an upper bound)."""
    return math.nextafter(x, inf)


class Interval:
    """The closed interval ``[lo, hi]`` of reals (see the module docstring for the contract)."""

    __slots__ = ("_lo", "_hi")

    def __init__(self, lo: float, hi: float) -> None:
        lo, hi = float(lo), float(hi)
        if not lo <= hi:
            raise ValueError(f"not an interval: [{lo}, {hi}]")
        if lo == inf or hi == -inf:
            raise ValueError(f"interval [{lo}, {hi}] holds no real")
        self._lo = lo
        self._hi = hi

    @classmethod
    def point(cls, x: float) -> Interval:
        """The degenerate interval ``[x, x]``."""
        return cls(x, x)

    @property
    def lo(self) -> float:
        return self._lo

    @property
    def hi(self) -> float:
        return self._hi

    @property
    def width(self) -> float:
        """``hi - lo`` as a float (``inf`` when unbounded)."""
        return self._hi - self._lo

    @property
    def mid(self) -> float:
        """A finite point of the interval: the midpoint; for the real line 0; for a half-line 0 when
        it lies well inside, else a point farther out than the finite bound (so :meth:`split` makes progress)."""
        lo, hi = self._lo, self._hi
        if lo == -inf:
            return 0.0 if hi == inf else max(-_MAX, min(0.0, 2.0 * hi - 1.0))
        if hi == inf:
            return min(_MAX, max(0.0, 2.0 * lo + 1.0))
        m = 0.5 * (lo + hi)
        return m if abs(m) < inf else 0.5 * lo + 0.5 * hi

    @property
    def is_point(self) -> bool:
        return self._lo == self._hi

    def contains(self, x: float) -> bool:
        return self._lo <= x <= self._hi

    def intersects(self, other: Interval) -> bool:
        return self._lo <= other._hi and other._lo <= self._hi

    def intersection(self, other: Interval) -> Interval | None:
        lo, hi = max(self._lo, other._lo), min(self._hi, other._hi)
        return _make(lo, hi) if lo <= hi else None

    def hull(self, other: Interval) -> Interval:
        return _make(min(self._lo, other._lo), max(self._hi, other._hi))

    def split(self) -> tuple[Interval, Interval]:
        """The two halves ``[lo, mid]`` and ``[mid, hi]``."""
        m = self.mid
        return _make(self._lo, m), _make(m, self._hi)

    def __repr__(self) -> str:
        return f"Interval({self._lo!r}, {self._hi!r})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Interval):
            return NotImplemented
        return self._lo == other._lo and self._hi == other._hi

    def __hash__(self) -> int:
        return hash((self._lo, self._hi))

    def __neg__(self) -> Interval:
        return _make(-self._hi, -self._lo)

    def __add__(self, other: Interval | float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _add(self, o)

    def __radd__(self, other: float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _add(o, self)

    def __sub__(self, other: Interval | float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _sub(self, o)

    def __rsub__(self, other: float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _sub(o, self)

    def __mul__(self, other: Interval | float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _mul(self, o)

    def __rmul__(self, other: float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _mul(o, self)

    def __truediv__(self, other: Interval | float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _div(self, o)

    def __rtruediv__(self, other: float) -> Interval:
        o = _operand(other)
        return NotImplemented if o is None else _div(o, self)


_new = object.__new__


def _make(lo: float, hi: float) -> Interval:
    """An interval from bounds already known to be valid (skips the checks of ``__init__``)."""
    iv = _new(Interval)
    iv._lo = lo
    iv._hi = hi
    return iv


def _operand(x: object) -> Interval | None:
    """``x`` as an interval, or None when it is not a number (the operator then defers)."""
    if isinstance(x, Interval):
        return x
    if isinstance(x, int | float):
        return Interval.point(x)
    return None


REALS = _make(-inf, inf)
_UNIT = _make(-1.0, 1.0)
_TURN = _make(-PI_HI, PI_HI)  # all angles in (-π, π]
_HALF_TURN = _make(0.0, PI_HI)  # all angle distances in [0, π]


# ----------------------------------------------------------------------------- arithmetic
def _add(a: Interval, b: Interval) -> Interval:
    return _make(_lower(a._lo + b._lo), _upper(a._hi + b._hi))


def _sub(a: Interval, b: Interval) -> Interval:
    return _make(_lower(a._lo - b._hi), _upper(a._hi - b._lo))


def _times(p: float, q: float) -> float:
    """``p * q`` with ``0 * inf = 0`` (a bound of 0 times an unbounded factor stays 0)."""
    return 0.0 if p == 0.0 or q == 0.0 else p * q


def _mul(a: Interval, b: Interval) -> Interval:
    p, q, r, s = _times(a._lo, b._lo), _times(a._lo, b._hi), _times(a._hi, b._lo), _times(a._hi, b._hi)
    return _make(_lower(min(p, q, r, s)), _upper(max(p, q, r, s)))


def _over(p: float, q: float) -> float:
    """``p / q`` for ``q != 0`` with ``p / ±inf = 0`` (the limit of the reciprocal times ``p``)."""
    return p / q if -inf < q < inf else 0.0


def _div(a: Interval, b: Interval) -> Interval:
    if b._lo <= 0.0 <= b._hi:
        if b._lo == b._hi:
            raise ZeroDivisionError("interval division by [0, 0]")
        return REALS
    p, q, r, s = _over(a._lo, b._lo), _over(a._lo, b._hi), _over(a._hi, b._lo), _over(a._hi, b._hi)
    return _make(_lower(min(p, q, r, s)), _upper(max(p, q, r, s)))


# ----------------------------------------------------------------------------- elementary functions
def _mig(x: Interval) -> float:
    """The smallest magnitude in ``x``."""
    if x._lo > 0.0:
        return x._lo
    return -x._hi if x._hi < 0.0 else 0.0


def _mag(x: Interval) -> float:
    """The largest magnitude in ``x``."""
    return max(-x._lo, x._hi)


def abs_(x: Interval) -> Interval:
    return _make(_mig(x), _mag(x))


def sqr(x: Interval) -> Interval:
    """``x ** 2``, tight: ``[0, ...]`` when ``x`` holds 0."""
    m, big = _mig(x), _mag(x)
    return _make(0.0 if m == 0.0 else _lower(m * m), _upper(big * big))


def _pow(b: float, n: int) -> float:
    try:
        return b**n
    except OverflowError:
        return -inf if b < 0.0 and n % 2 else inf


def power(x: Interval, n: int) -> Interval:
    """``x ** n`` for an integer ``n >= 0`` (``x ** 0 = [1, 1]``)."""
    if not isinstance(n, int) or n < 0:
        raise ValueError(f"power needs an integer exponent >= 0, not {n!r}")
    if n < 2:
        return x if n else _make(1.0, 1.0)
    if n % 2:
        return _make(_lower(_pow(x._lo, n)), _upper(_pow(x._hi, n)))
    m = _mig(x)
    return _make(0.0 if m == 0.0 else _lower(_pow(m, n)), _upper(_pow(_mag(x), n)))


def sqrt(x: Interval) -> Interval | None:
    """``√x`` over the part of ``x`` where it is defined (``x >= 0``); None when there is none."""
    if x._hi < 0.0:
        return None
    lo = x._lo if x._lo > 0.0 else 0.0
    return _make(0.0 if lo == 0.0 else _lower(math.sqrt(lo)), _upper(math.sqrt(x._hi)))


def minimum(a: Interval, b: Interval) -> Interval:
    return _make(min(a._lo, b._lo), min(a._hi, b._hi))


def maximum(a: Interval, b: Interval) -> Interval:
    return _make(max(a._lo, b._lo), max(a._hi, b._hi))


def hypot(x: Interval, y: Interval) -> Interval:
    """``√(x² + y²)``."""
    lo = math.hypot(_mig(x), _mig(y))
    return _make(0.0 if lo == 0.0 else _lower(lo), _upper(math.hypot(_mag(x), _mag(y))))


# ----------------------------------------------------------------------------- trigonometry
def _hits(first: int, last: int, residue: int) -> bool:
    """Whether some integer in ``[first, last]`` is ``residue`` modulo 4."""
    return first + (residue - first) % 4 <= last


def _periodic(x: Interval, f: Callable[[float], float], peak: int) -> Interval:
    """The range of ``f`` (sin or cos) over ``x``; ``f`` is 1 at the quarter turns ``k π/2`` with
    ``k = peak (mod 4)`` and -1 at ``k = peak + 2``. The quarter turns that *may* lie in ``x`` are
    found with a small relative slack, so a rounding error can only include an extremum."""
    lo, hi = x._lo, x._hi
    if not hi - lo < TWO_PI:
        return _UNIT
    first, last = lo / HALF_PI, hi / HALF_PI
    first = math.ceil(first - abs(first) * _SLACK)
    last = math.floor(last + abs(last) * _SLACK)
    a, b = f(lo), f(hi)
    top = 1.0 if _hits(first, last, peak) else min(1.0, _upper(max(a, b)))
    bottom = -1.0 if _hits(first, last, peak + 2) else max(-1.0, _lower(min(a, b)))
    return _make(bottom, top)


def sin(x: Interval) -> Interval:
    return _periodic(x, math.sin, 1)


def cos(x: Interval) -> Interval:
    return _periodic(x, math.cos, 0)


def _angle_range(y0: float, y1: float, x0: float, x1: float) -> tuple[float, float]:
    """The least and greatest ``math.atan2`` over the corners of the box ``[x0, x1] × [y0, y1]``."""
    a, b, c, d = math.atan2(y0, x0), math.atan2(y0, x1), math.atan2(y1, x0), math.atan2(y1, x1)
    return min(a, b, c, d), max(a, b, c, d)


def atan2(y: Interval, x: Interval) -> Interval:
    """The angle of the points ``(x, y)`` of the box: ``[-π, π]`` when the box holds the origin;
    unwrapped (within ``(π/2, 3π/2)``) when the box crosses the negative x-axis, the branch cut;
    otherwise within ``[-π, π]``. Off the origin, the extremes lie at the box's corners."""
    if x._lo <= 0.0 <= x._hi and y._lo <= 0.0 <= y._hi:
        return _TURN
    if x._hi < 0.0 and y._lo <= 0.0 <= y._hi:
        # the angle of (x, y) is π + the angle of (-x, -y), which is continuous in the right half-plane
        lo, hi = _angle_range(-y._hi, -y._lo, -x._hi, -x._lo)
        return _make(_lower(_lower(lo) + PI_LO), _upper(_upper(hi) + PI_HI))
    lo, hi = _angle_range(y._lo, y._hi, x._lo, x._hi)
    return _make(_lower(lo), _upper(hi))


# ----------------------------------------------------------------------------- angles
def normalize(x: float) -> float:
    """``x`` shifted by a multiple of 2π into ``(-π, π]`` (float arithmetic, not an enclosure)."""
    r = math.remainder(x, TWO_PI)
    return r + TWO_PI if r <= -PI_LO else r


def angle_distance_bounds(iv: Interval, target: float) -> Interval:
    """Encloses ``{|normalize(v - target)| : v in iv}``, the angular distances to ``target`` (in ``[0, π]``).

    The distance of ``u = v - target`` is ``min_k |u - 2πk|``. When the interval ``[a, b]`` of ``u``
    is narrower than 2π, the nearest ``k`` is one of three around its midpoint; the range is the
    least (and the least of the greatest) distance from ``[a, b]`` to those three points, capped at π."""
    a, b = _lower(iv._lo - target), _upper(iv._hi - target)
    if not (b - a < TWO_PI and abs(a) < _TURNS_EXACT):
        return _HALF_TURN
    k = round((0.5 * a + 0.5 * b) / TWO_PI)
    lo = hi = PI_HI
    for turns in (k - 1, k, k + 1):
        # [c0, c1] encloses 2π * turns (TWO_PI < 2π < TWO_PI_HI; turns is exact as a float)
        c0, c1 = (turns * TWO_PI, turns * TWO_PI_HI) if turns >= 0 else (turns * TWO_PI_HI, turns * TWO_PI)
        c0, c1 = _lower(c0), _upper(c1)
        lo = min(lo, max(0.0, _lower(a - c1), _lower(c0 - b)))
        hi = min(hi, _upper(max(b - c0, c1 - a)))
    return _make(lo, hi)


def angle_may_be_within(iv: Interval, target: float, tol: float) -> bool:
    """Whether some ``v`` in ``iv`` may be within ``tol`` of ``target`` (never False when one is)."""
    return angle_distance_bounds(iv, target)._lo <= tol


def angle_surely_within(iv: Interval, target: float, tol: float) -> bool:
    """Whether every ``v`` in ``iv`` is within ``tol`` of ``target`` (never True when one is not)."""
    return angle_distance_bounds(iv, target)._hi <= tol


# ----------------------------------------------------------------------------- plane vectors
def rotate(x: Interval, y: Interval, angle: Interval | float) -> tuple[Interval, Interval]:
    """The vector ``(x, y)`` rotated counter-clockwise by ``angle``:
    ``(x cos θ - y sin θ, x sin θ + y cos θ)`` (sound, not tight: ``cos`` and ``sin`` vary independently)."""
    theta = angle if isinstance(angle, Interval) else Interval.point(angle)
    c, s = cos(theta), sin(theta)
    return x * c - y * s, x * s + y * c
