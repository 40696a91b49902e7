"""Interval arithmetic (scene/solvers/intervals.py): soundness on random intervals and points inside
them, checked exactly with fractions where the real result is rational, and against ``math`` elsewhere;
tightness spot checks with hand-computed values; edge cases (infinities, zero, the angle wrap)."""

import math
import operator
import sys
from fractions import Fraction

import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from scenegrep.scene.solvers import intervals as iv
from scenegrep.scene.solvers.intervals import Interval

inf = math.inf
PI = math.pi
ULP = 1e-15  # "up to outward rounding": a few ulps, relative to the value (or absolute below 1)


@st.composite
def members(draw, limit: float = 1e300, unbounded: bool = True) -> tuple[Interval, float]:
    """An interval (bounds within ``limit``, sometimes infinite) and a finite point inside it."""
    a, b = sorted((draw(st.floats(-limit, limit)) + 0.0, draw(st.floats(-limit, limit)) + 0.0))  # + 0.0: no -0.0
    point = draw(st.floats(a, b))
    if unbounded:
        a = draw(st.sampled_from([a, a, a, -inf]))
        b = draw(st.sampled_from([b, b, b, inf]))
    return Interval(a, b), point


angles = members(limit=20.0, unbounded=False)
small = members(limit=1e3)


def encloses(interval: Interval, exact: Fraction | float) -> bool:
    """Exact comparison: fractions compare with floats (and infinities) without rounding."""
    return interval.lo <= exact <= interval.hi


def root_encloses(interval: Interval, square: Fraction) -> bool:
    """Whether the non-negative ``interval`` holds the real square root of ``square``, tested exactly."""
    return Fraction(interval.lo) ** 2 <= square and (interval.hi == inf or square <= Fraction(interval.hi) ** 2)


def angle_gap(value: float, interval: Interval) -> float:
    """How far ``value + 2πk`` is outside ``interval`` for the best ``k`` (0 when inside)."""
    return min(max(interval.lo - (value + k * 2 * PI), (value + k * 2 * PI) - interval.hi, 0.0) for k in (-1, 0, 1))


# ----------------------------------------------------------------------------- soundness
OPS = {"add": operator.add, "sub": operator.sub, "mul": operator.mul, "div": operator.truediv}


@pytest.mark.parametrize("op", OPS.values(), ids=OPS.keys())
@given(members(), members())
def test_arithmetic_encloses_the_exact_result(op, xp, yq):
    (x, p), (y, q) = xp, yq
    assume(op is not operator.truediv or q != 0.0)
    exact = op(Fraction(p), Fraction(q))
    for result in (op(x, y), op(x, q), op(p, y)):
        assert encloses(result, exact), (x, y, result, float(exact))


@given(members())
def test_negation_is_exact(xp):
    x, p = xp
    assert (-x).lo == -x.hi and encloses(-x, -p)


@given(members(), st.integers(0, 9))
def test_powers_enclose_the_exact_result(xp, n):
    x, p = xp
    assert encloses(iv.sqr(x), Fraction(p) ** 2)
    assert encloses(iv.power(x, n), Fraction(p) ** n)
    assert encloses(iv.abs_(x), abs(p))


@given(members())
def test_sqrt_encloses_the_exact_root(xp):
    x, p = xp
    root = iv.sqrt(x)
    if x.hi < 0:
        assert root is None
        return
    assert root.lo >= 0.0
    if p >= 0:
        assert root_encloses(root, Fraction(p))
        assert encloses(root, math.sqrt(p))


@given(members(), members())
def test_hypot_min_max_enclose_the_exact_result(xp, yq):
    (x, p), (y, q) = xp, yq
    h = iv.hypot(x, y)
    assert h.lo >= 0.0 and root_encloses(h, Fraction(p) ** 2 + Fraction(q) ** 2)
    assert encloses(iv.minimum(x, y), min(p, q))
    assert encloses(iv.maximum(x, y), max(p, q))


@given(st.one_of(angles, members(limit=1e9)))
def test_sin_cos_enclose_math(xp):
    x, p = xp
    s, c = iv.sin(x), iv.cos(x)
    assert encloses(s, math.sin(p)) and encloses(c, math.cos(p))
    assert -1.0 <= s.lo and s.hi <= 1.0 and -1.0 <= c.lo and c.hi <= 1.0


@given(small, small)
def test_atan2_encloses_the_angle_modulo_2pi(yq, xp):
    (y, q), (x, p) = yq, xp
    result = iv.atan2(y, x)
    assert angle_gap(math.atan2(q, p), result) <= ULP, (y, x, result)  # slack for the float shift by 2π
    assert result.width <= 2 * PI + ULP


@given(angles, angles, angles)
def test_rotate_encloses_the_float_rotation(xp, yq, at):
    (x, p), (y, q), (a, t) = xp, yq, at
    c, s = math.cos(t), math.sin(t)
    rx, ry = iv.rotate(x, y, a)
    assert encloses(rx, p * c - q * s) and encloses(ry, p * s + q * c)
    px, py = iv.rotate(x, y, t)
    assert encloses(px, p * c - q * s) and encloses(py, p * s + q * c)


@given(st.floats(-1e6, 1e6))
def test_normalize_lands_in_the_half_open_turn(x):
    r = iv.normalize(x)
    assert -PI < r <= PI
    turns = (x - r) / (2 * PI)
    assert abs(turns - round(turns)) <= 1e-9


@given(angles, st.floats(-4.0, 4.0), st.floats(0.0, 3.5))
def test_angle_distance_bounds_are_sound(vp, target, tol):
    v, p = vp
    bounds = iv.angle_distance_bounds(v, target)
    distance = abs(iv.normalize(p - target))
    assert 0.0 <= bounds.lo and bounds.hi <= PI + ULP
    assert bounds.lo - 1e-12 <= distance <= bounds.hi + 1e-12
    if distance <= tol - 1e-12:
        assert iv.angle_may_be_within(v, target, tol)
    if iv.angle_surely_within(v, target, tol):
        assert distance <= tol + 1e-12


@given(members())
def test_mid_and_split(xp):
    x, _ = xp
    m = x.mid
    assert math.isfinite(m) and x.contains(m)
    left, right = x.split()
    assert left.hull(right) == x and left.hi == right.lo == m
    if x.lo == -inf or x.hi == inf:
        assert left != x and right != x  # an unbounded interval splits into two new pieces


# ----------------------------------------------------------------------------- tightness
def close(interval: Interval, lo: float, hi: float, tol: float = ULP) -> bool:
    """``interval`` holds ``[lo, hi]`` and exceeds it by at most ``tol`` (relative beyond 1) on each side."""
    outside_lo = 0.0 if interval.lo == lo else lo - interval.lo
    outside_hi = 0.0 if interval.hi == hi else interval.hi - hi
    return 0.0 <= outside_lo <= tol * max(1.0, abs(lo)) and 0.0 <= outside_hi <= tol * max(1.0, abs(hi))


def test_sin_cos_are_tight():
    assert close(iv.sin(Interval(0.0, PI)), 0.0, 1.0) and iv.sin(Interval(0.0, PI)).hi == 1.0
    assert iv.cos(Interval(0.0, PI)) == Interval(-1.0, 1.0)
    assert close(iv.cos(Interval(-PI / 3, PI / 3)), 0.5, 1.0)
    assert close(iv.sin(Interval(0.1, 0.2)), math.sin(0.1), math.sin(0.2))
    assert close(iv.cos(Interval(4.0, 5.0)), math.cos(4.0), math.cos(5.0))
    assert close(iv.sin(Interval(2.0, 4.0)), math.sin(4.0), math.sin(2.0))
    assert close(iv.sin(Interval(-PI / 2 - 0.5, -PI / 2 + 0.25)), -1.0, math.sin(-PI / 2 - 0.5))
    assert iv.sin(Interval(1.0, 1.0 + 2 * PI)) == Interval(-1.0, 1.0)
    assert iv.cos(Interval(-inf, 0.0)) == Interval(-1.0, 1.0)


def test_powers_are_tight():
    assert iv.sqr(Interval(-2.0, 3.0)).lo == 0.0 and close(iv.sqr(Interval(-2.0, 3.0)), 0.0, 9.0)
    assert close(iv.sqr(Interval(-3.0, -2.0)), 4.0, 9.0)
    assert close(iv.power(Interval(-2.0, 1.0), 3), -8.0, 1.0, 1e-14)
    assert iv.power(Interval(-2.0, 1.0), 4).lo == 0.0
    assert iv.power(Interval(-inf, 5.0), 0) == Interval.point(1.0)
    assert iv.power(Interval(1e200, 1e200), 3).hi == inf
    assert iv.power(Interval(-1e200, -1e200), 3).lo == -inf
    assert iv.power(Interval(2.0, 3.0), 1) == Interval(2.0, 3.0)


def test_arithmetic_is_tight():
    assert close(Interval(1.0, 2.0) + Interval(3.0, 4.0), 4.0, 6.0)
    assert close(Interval(1.0, 2.0) - Interval(3.0, 4.0), -3.0, -1.0)
    assert close(Interval(-1.0, 2.0) * Interval(3.0, 4.0), -4.0, 8.0)
    assert close(1.0 / Interval(2.0, 4.0), 0.25, 0.5)
    assert close(Interval(-6.0, 3.0) / Interval(-3.0, -1.5), -2.0, 4.0)
    assert close(5.0 - Interval(1.0, 2.0), 3.0, 4.0) and close(2 * Interval(1.0, 2.0), 2.0, 4.0)
    assert iv.abs_(Interval(-3.0, 2.0)) == Interval(0.0, 3.0) and iv.abs_(Interval(-3.0, -2.0)) == Interval(2.0, 3.0)
    assert iv.minimum(Interval(0.0, 5.0), Interval(1.0, 2.0)) == Interval(0.0, 2.0)
    assert iv.maximum(Interval(0.0, 5.0), Interval(1.0, 2.0)) == Interval(1.0, 5.0)
    assert close(iv.hypot(Interval(3.0, 3.0), Interval(-4.0, -4.0)), 5.0, 5.0)
    assert iv.hypot(Interval(-1.0, 3.0), Interval(-4.0, 2.0)).lo == 0.0


def test_outward_rounding_contains_the_real_sum():
    s = Interval.point(0.1) + Interval.point(0.2)
    assert 0.1 + 0.2 != Fraction(0.1) + Fraction(0.2)  # the float sum is rounded ...
    assert encloses(s, Fraction(0.1) + Fraction(0.2)) and s.lo < 0.1 + 0.2 < s.hi  # ... the interval holds both
    assert not s.is_point and s.width < 1e-15


def test_atan2_is_tight_and_unwrapped_across_the_branch_cut():
    cut = iv.atan2(Interval(-0.5, 0.5), Interval(-2.0, -1.0))
    assert cut.hi > PI and cut.width < PI / 2
    assert close(cut, PI - math.atan(0.5), PI + math.atan(0.5), 1e-14)
    touching = iv.atan2(Interval(-1.0, 0.0), Interval(-2.0, -1.0))
    assert close(touching, PI, PI + math.atan(1.0), 1e-14)
    assert close(iv.atan2(Interval(1.0, 2.0), Interval(1.0, 2.0)), math.atan2(1, 2), math.atan2(2, 1))
    assert close(iv.atan2(Interval(1.0, 2.0), Interval(-1.0, 1.0)), math.atan2(1, 1), math.atan2(1, -1))
    assert close(iv.atan2(Interval(-2.0, -1.0), Interval(-3.0, -1.0)), math.atan2(-1, -3), math.atan2(-2, -1))
    full = iv.atan2(Interval(-1.0, 1.0), Interval(0.0, 1.0))
    assert full.lo <= -PI and full.hi >= PI and full.width <= 2 * PI + ULP
    assert close(iv.atan2(Interval(1.0, inf), Interval(-inf, inf)), 0.0, PI)


def test_angle_distance_is_tight():
    assert close(iv.angle_distance_bounds(Interval(0.5, 1.0), 0.0), 0.5, 1.0)
    assert close(iv.angle_distance_bounds(Interval(-0.5, 1.0), 0.0), 0.0, 1.0)
    assert close(iv.angle_distance_bounds(Interval(3.0, 3.5), 0.0), 2 * PI - 3.5, PI)
    assert close(iv.angle_distance_bounds(Interval(2 * PI + 0.5, 2 * PI + 1.0), 0.0), 0.5, 1.0, 1e-14)
    assert iv.angle_distance_bounds(Interval(0.0, 7.0), 1.0) == Interval(0.0, iv.PI_HI)
    assert iv.angle_distance_bounds(Interval(-inf, 0.0), 1.0) == Interval(0.0, iv.PI_HI)


# ----------------------------------------------------------------------------- edge cases
def test_the_angle_wrap_near_pi():
    assert iv.angle_may_be_within(Interval(-3.14, -3.1), 3.1, 0.1)
    assert iv.angle_surely_within(Interval(-3.14, -3.1), 3.1, 0.1)
    assert close(iv.angle_distance_bounds(Interval(-3.14, -3.1), 3.1), 2 * PI - 6.24, 2 * PI - 6.2, 1e-14)
    assert not iv.angle_may_be_within(Interval(-3.0, -2.9), 3.1, 0.1)
    assert iv.angle_may_be_within(Interval(PI - 0.01, PI), -PI + 0.05, 0.1)
    assert not iv.angle_surely_within(Interval(0.0, 0.3), 0.0, 0.2)


def test_division_by_intervals_holding_zero():
    assert Interval(1.0, 2.0) / Interval(-1.0, 1.0) == iv.REALS
    assert Interval(1.0, 2.0) / Interval(0.0, 1.0) == iv.REALS
    with pytest.raises(ZeroDivisionError):
        Interval(1.0, 2.0) / Interval(0.0, 0.0)
    with pytest.raises(ZeroDivisionError):
        Interval(1.0, 2.0) / 0


def test_infinities():
    assert Interval(-inf, inf) + 1.0 == iv.REALS
    assert close(Interval(0.0, inf) * Interval(0.0, 0.0), 0.0, 0.0)  # 0 * inf counts as 0, not NaN
    assert close(Interval(-inf, 2.0) * Interval(0.0, 3.0), -inf, 6.0)
    assert close(Interval(1.0, inf) / Interval(1.0, inf), 0.0, inf)  # inf / inf bounds are limits, not NaN
    assert close(Interval(-inf, -1.0) / Interval(-inf, -1.0), 0.0, inf)
    assert close(Interval(1.0, 2.0) / Interval(-inf, -1.0), -2.0, 0.0)
    assert Interval.point(1e308) + 1e308 == Interval(sys.float_info.max, inf)  # overflow stays enclosed
    assert iv.sqrt(Interval(4.0, inf)).hi == inf and iv.hypot(Interval(-inf, 0.0), Interval.point(1.0)).hi == inf
    assert iv.abs_(Interval(-inf, -2.0)) == Interval(2.0, inf)


def test_sqrt_of_partly_negative_intervals():
    root = iv.sqrt(Interval(-4.0, 9.0))
    assert root.lo == 0.0 and close(root, 0.0, 3.0)
    assert iv.sqrt(Interval(-4.0, -1.0)) is None
    assert iv.sqrt(Interval(-4.0, 0.0)).lo == 0.0 and iv.sqrt(Interval(-4.0, 0.0)).hi <= 5e-324


def test_degenerate_point_intervals():
    p = Interval.point(2.0)
    assert p.is_point and p.width == 0.0 and p.mid == 2.0 and p.split() == (p, p)
    assert close(p * p, 4.0, 4.0) and close(iv.sqrt(p), math.sqrt(2), math.sqrt(2))
    assert close(iv.cos(Interval.point(0.0)), 1.0, 1.0) and iv.cos(Interval.point(0.0)).hi == 1.0
    assert (p - p).contains(0.0) and (p - p).width < 1e-15


def test_construction_and_set_operations():
    for lo, hi in ((2.0, 1.0), (math.nan, 1.0), (0.0, math.nan), (inf, inf), (-inf, -inf)):
        with pytest.raises(ValueError):
            Interval(lo, hi)
    x = Interval(0, 2)
    assert x == Interval(0.0, 2.0) and hash(x) == hash(Interval(0.0, 2.0)) and repr(x) == "Interval(0.0, 2.0)"
    assert x != (0.0, 2.0) and x.contains(2.0) and not x.contains(2.5)
    with pytest.raises(AttributeError):
        x.lo = 1.0
    assert x.intersects(Interval(2.0, 3.0)) and not x.intersects(Interval(2.5, 3.0))
    assert x.intersection(Interval(1.0, 3.0)) == Interval(1.0, 2.0) and x.intersection(Interval(3.0, 4.0)) is None
    assert x.hull(Interval(5.0, 6.0)) == Interval(0.0, 6.0)
    assert x.split() == (Interval(0.0, 1.0), Interval(1.0, 2.0))
    assert Interval(-inf, inf).mid == 0.0 and Interval(-inf, -4.0).mid == -9.0 and Interval(3.0, inf).mid == 7.0
    with pytest.raises(TypeError):
        x + "1"
    with pytest.raises(ValueError):
        iv.power(x, -1)
