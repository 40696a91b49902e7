"""The inverted walk's reach test in C (:func:`scenegrep.scene.follow_inverse._narrowed`, the C
pass of ``scene/_reach.c``) gives bit for bit what the numpy code it replaced gave (kept here as
the reference: the stadium hull, then its narrowing to where the centreline's nearest point may
lie on the segment), on random rows with every degenerate kind: segments and swept segments of no
length, points on the segment's line and at its ends, missing neighbours, neighbours folding back,
infinite radii; and with ``nearest=False`` the stadium alone."""

from __future__ import annotations

import numpy as np
import pytest

from scenegrep.scene.follow_inverse import DEGENERATE_M, FOOT_SLACK_M, _narrowed


def _nearest_on(p, r, ends, unit, neighbours, span) -> tuple[np.ndarray, np.ndarray]:
    """``span`` ([t_lo, t_hi] per row) narrowed to the hull of the t at which the nearest point of
    its centreline to p + t r may lie on the segment ``ends`` (its start rows, its end rows;
    ``unit``: its direction): dropped are the t at which the point lies :data:`FOOT_SLACK_M` or
    more before the start along it and along the segment before (``neighbours[0]``: its direction;
    NaN: none), whose end is then nearer, and likewise past the end along it and the segment after
    (``neighbours[1]``). Call with numpy's divide and invalid warnings off."""
    low, high = span
    vertex = np.stack([ends[0], ends[0], ends[1], ends[1]])
    direction = np.stack([unit, neighbours[0], unit, neighbours[1]])
    sign = np.array([[-1.0], [-1.0], [1.0], [1.0]])
    along = sign * np.einsum("kij,kij->ki", p - vertex, direction)
    rate = sign * np.einsum("ij,kij->ki", r, direction)
    f_lo, f_hi = _linear_bounds(along, rate, FOOT_SLACK_M, np.inf)
    f_lo = np.maximum(np.maximum(0.0, f_lo[0::2]), f_lo[1::2])
    f_hi = np.minimum(np.minimum(1.0, f_hi[0::2]), f_hi[1::2])
    none = np.isnan(f_lo) | np.isnan(f_hi) | np.isnan(direction[1::2, :, 0])
    f_lo, f_hi = np.where(none, np.inf, f_lo), np.where(none, -np.inf, f_hi)
    for _ in range(2):
        for k in range(2):
            low = np.where((low >= f_lo[k]) & (low <= f_hi[k]), f_hi[k], low)
            high = np.where((high >= f_lo[k]) & (high <= f_hi[k]), f_lo[k], high)
    return low, high


def _stadium(p, r, a, b, radius) -> tuple[np.ndarray, np.ndarray]:
    """The hull [t_lo, t_hi] (t_lo > t_hi: empty) of the t in [0, 1] at which p + t r lies within
    ``radius`` of the segment a-b: the union of the band along it and the discs at its ends. Call
    with numpy's divide and invalid warnings off."""
    w = b - a
    ww = np.einsum("ij,ij->i", w, w)
    length = np.sqrt(ww)
    pa = p - a
    f0 = np.stack([np.einsum("ij,ij->i", pa, w) / ww, _cross(w, pa) / length])
    f1 = np.stack([np.einsum("ij,ij->i", r, w) / ww, _cross(w, r) / length])
    zero = np.zeros(len(p))
    low, high = _linear_bounds(f0, f1, np.stack([zero, -radius]), np.stack([zero + 1.0, radius]))
    band = ww > 0
    low = np.where(band, np.maximum(np.maximum(0.0, low[0]), low[1]), np.inf)
    high = np.where(band, np.minimum(np.minimum(1.0, high[0]), high[1]), -np.inf)
    disc_lo, disc_hi = _quadratic_below(r, np.stack([pa, p - b]), radius)
    lows, highs = np.concatenate([disc_lo, low[None]]), np.concatenate([disc_hi, high[None]])
    empty = lows > highs
    return np.where(empty, np.inf, lows).min(axis=0), np.where(empty, -np.inf, highs).max(axis=0)


def _quadratic_below(r, d, radius) -> tuple[np.ndarray, np.ndarray]:
    """The t in [0, 1] with |d[k] + t r| <= radius (``d``: a stack of row sets, each like ``r``),
    as intervals (low > high: none; an empty one may be infinite). Call with numpy's divide and
    invalid warnings off."""
    rr = np.einsum("ij,ij->i", r, r)
    dr = np.einsum("kij,ij->ki", d, r)
    c = np.einsum("kij,kij->ki", d, d) - radius * radius
    moving = rr > DEGENERATE_M**2
    disc = dr * dr - rr * c
    root = np.sqrt(np.where(disc >= 0, disc, np.nan))
    low = np.where(moving, (-dr - root) / rr, np.where(c <= 0, 0.0, np.inf))
    high = np.where(moving, (-dr + root) / rr, np.where(c <= 0, 1.0, -np.inf))
    none = np.isnan(low) | np.isnan(high)
    return np.where(none, np.inf, np.maximum(low, 0.0)), np.where(none, -np.inf, np.minimum(high, 1.0))


def _linear_bounds(f0, f1, bottom, top) -> tuple[np.ndarray, np.ndarray]:
    """The t where bottom <= f0 + f1 t <= top, as intervals (low > high: none; -inf, inf: every
    t), to be intersected with the others by maximum and minimum (NaN where f0 or f1 is)."""
    u, v = (bottom - f0) / f1, (top - f0) / f1
    flat = np.abs(f1) <= 1e-300
    inside = (f0 >= bottom) & (f0 <= top)
    low = np.where(flat, np.where(inside, -np.inf, np.inf), np.minimum(u, v))
    high = np.where(flat, np.where(inside, np.inf, -np.inf), np.maximum(u, v))
    return low, high


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]


def rows(seed: int, n: int):
    """Random rows of (p, r, a, z, radius, unit, before, after), a tenth of each degenerate kind."""
    rng = np.random.default_rng(seed)
    a = rng.normal(0, 3, (n, 2))
    z = a + rng.normal(0, 0.4, (n, 2))
    p = rng.normal(0, 3, (n, 2))
    r = rng.normal(0, 3, (n, 2))
    radius = rng.uniform(0.5, 3.0, n)
    kind = rng.integers(0, 10, n)
    z[kind == 1] = a[kind == 1]
    r[kind == 2] = 0.0
    p[kind == 3] = a[kind == 3] + rng.uniform(-1, 2, (np.count_nonzero(kind == 3), 1)) * (z - a)[kind == 3]
    p[kind == 4] = z[kind == 4]
    radius[kind == 5] = np.inf
    r[kind == 6] = (z - a)[kind == 6] * rng.uniform(-3, 3, (np.count_nonzero(kind == 6), 1))
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = (z - a) / np.hypot(*(z - a).T)[:, None]
    turn = rng.uniform(-3.2, 3.2, (2, n))
    before = np.stack(
        [
            np.cos(turn[0]) * unit[:, 0] - np.sin(turn[0]) * unit[:, 1],
            np.sin(turn[0]) * unit[:, 0] + np.cos(turn[0]) * unit[:, 1],
        ],
        axis=1,
    )
    after = np.stack(
        [
            np.cos(turn[1]) * unit[:, 0] - np.sin(turn[1]) * unit[:, 1],
            np.sin(turn[1]) * unit[:, 0] + np.cos(turn[1]) * unit[:, 1],
        ],
        axis=1,
    )
    before[kind == 7] = np.nan
    after[kind == 8] = np.nan
    before[kind == 9] = -unit[kind == 9]
    return p, r, a, z, radius, unit, before, after


def same(x: np.ndarray, y: np.ndarray) -> bool:
    return bool(np.all((x == y) | (np.isnan(x) & np.isnan(y))))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_c_pass_gives_the_numpy_formulas_bit_for_bit(seed):
    p, r, a, z, radius, unit, before, after = rows(seed, 20000)
    with np.errstate(divide="ignore", invalid="ignore"):
        span = _stadium(p, r, a, z, radius)
        expected = _nearest_on(p, r, (a, z), unit, (before, after), span)
    assert same(_narrowed(p, r, a, z, radius, unit, before, after, nearest=False)[0], span[0])
    assert same(_narrowed(p, r, a, z, radius, unit, before, after, nearest=False)[1], span[1])
    low, high = _narrowed(p, r, a, z, radius, unit, before, after)
    assert same(low, expected[0]) and same(high, expected[1])
    assert np.count_nonzero(low <= high) > 1000 and np.count_nonzero(low > high) > 1000


def test_rows_of_the_wrong_shape_are_refused():
    p, r, a, z, radius, unit, before, after = rows(3, 10)
    with pytest.raises(ValueError, match="radius"):
        _narrowed(p, r, a, z, radius[:5], unit, before, after)
