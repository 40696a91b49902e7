"""A transform buffer (ROS tf): frame links over time, looked up along a chain at any stamp.

Each child frame has one parent (the latest link received names it; a link naming another
parent replaces the child's history). A link's samples are kept sorted by stamp; at a stamp
between two samples the translation (and a velocity, an odometry twist) is interpolated
linearly and the rotation by slerp; at a sample's stamp it is that sample exactly. There is no
extrapolation: a stamp before a link's first sample or after its last is missing
(:class:`MissingTransform`). Static links
(``/tf_static``) hold at every stamp. Quaternions are (x, y, z, w).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .messages import Transforms

MAX_CHAIN = 64
"""The most links a chain may have (a longer one is a cycle or a hostile tree)."""


class MissingTransform(LookupError):
    """No transform at some stamp: ``row`` is the first stamp (position) without one."""

    def __init__(self, row: int, reason: str):
        super().__init__(reason)
        self.row = row
        self.reason = reason


Components = Sequence[np.ndarray]
"""A column of quaternions as its components (x, y, z, w), or of vectors as (x, y, z): one array
each (the hot paths work on contiguous components, not on (n, 4) rows)."""


def _sum(*terms: tuple[np.ndarray, np.ndarray, int]) -> np.ndarray:
    """p0 q0 ± p1 q1 ± ... of terms (p, q, sign), added from the left in place (the same bits as
    the plain expression, without a new array per operation)."""
    (p, q, _), *rest = terms
    out, scratch = np.multiply(p, q), np.empty(np.shape(p))
    for p, q, sign in rest:
        (np.add if sign > 0 else np.subtract)(out, np.multiply(p, q, out=scratch), out=out)
    return out


def product(a: Components, b: Components) -> tuple[np.ndarray, ...]:
    """The components of the Hamilton products a * b of quaternions."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        _sum((aw, bx, 1), (ax, bw, 1), (ay, bz, 1), (az, by, -1)),
        _sum((aw, by, 1), (ax, bz, -1), (ay, bw, 1), (az, bx, 1)),
        _sum((aw, bz, 1), (ax, by, 1), (ay, bx, -1), (az, bw, 1)),
        _sum((aw, bw, 1), (ax, bx, -1), (ay, by, -1), (az, bz, -1)),
    )


def rotated(q: Components, v: Components) -> tuple[np.ndarray, ...]:
    """The components (x, y, z) of vectors ``v`` rotated by unit quaternions ``q``: v + w t + u x t
    with t = 2 (u x v), for q = (u, w)."""
    ux, uy, uz, w = q
    vx, vy, vz = v
    tx, ty, tz = _sum((uy, vz, 1), (uz, vy, -1)), _sum((uz, vx, 1), (ux, vz, -1)), _sum((ux, vy, 1), (uy, vx, -1))
    for t in (tx, ty, tz):
        t *= 2.0
    out = []
    for value, along, cross in (
        (vx, tx, ((uy, tz, 1), (uz, ty, -1))),
        (vy, ty, ((uz, tx, 1), (ux, tz, -1))),
        (vz, tz, ((ux, ty, 1), (uy, tx, -1))),
    ):
        moved = np.multiply(w, along)
        moved += value
        moved += _sum(*cross)
        out.append(moved)
    return tuple(out)


def yaw(q: Components) -> np.ndarray:
    """Rotation about +z of quaternions (radians, counter-clockwise from +x)."""
    x, y, z, w = q
    sine, cosine = _sum((w, z, 1), (x, y, 1)), _sum((y, y, 1), (z, z, 1))
    sine *= 2.0
    cosine *= 2.0
    return np.arctan2(sine, np.subtract(1.0, cosine, out=cosine), out=sine)


def quat_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products a * b of (n, 4) quaternions (x, y, z, w)."""
    return np.stack(product(a.T, b.T), axis=1)


def quat_rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(n, 3) vectors ``v`` rotated by unit quaternions ``q`` (n, 4)."""
    return np.stack(rotated(q.T, v.T), axis=1)


def yaw_of(q: np.ndarray) -> np.ndarray:
    """Rotation about +z of (n, 4) quaternions (radians, counter-clockwise from +x)."""
    return yaw(q.T)


def normalised(q: np.ndarray) -> np.ndarray:
    """Unit quaternions (a zero quaternion, as some writers leave unset, is the identity)."""
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    return np.where(norm > 0, q / np.where(norm > 0, norm, 1.0), np.array([0.0, 0.0, 0.0, 1.0]))


def slerp(q0: np.ndarray, q1: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Spherical linear interpolation between unit quaternions at fractions ``t`` (n,)."""
    dot = np.sum(q0 * q1, axis=1)
    q1 = np.where(dot[:, None] < 0, -q1, q1)
    dot = np.abs(dot)
    close = dot > 0.9995
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    sin = np.where(close, 1.0, np.sin(theta))
    w0 = np.where(close, 1.0 - t, np.sin((1.0 - t) * theta) / sin)
    w1 = np.where(close, t, np.sin(t * theta) / sin)
    return normalised(w0[:, None] * q0 + w1[:, None] * q1)


@dataclass
class _Link:
    """A link's samples, sorted by stamp with one sample per stamp (the last received), in arrays
    that grow by appending (their capacity doubles), so adding samples in stamp order costs
    what they hold, not what the link holds; a sample out of order re-sorts them."""

    parent: str
    static: bool
    size: int = 0
    stamps: np.ndarray = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    values: np.ndarray = field(default_factory=lambda: np.empty((0, 10)))
    """Per sample: position (3), rotation (4), velocity (3; NaN unknown)."""
    moving: bool = False
    """Whether any sample came with a velocity (an odometry twist)."""

    def add(self, stamps: np.ndarray, xyz: np.ndarray, quat: np.ndarray, velocity: np.ndarray | None) -> None:
        stamps = np.asarray(stamps, dtype=np.int64)
        if not len(stamps):
            return
        self.moving |= velocity is not None
        velocity = np.full(xyz.shape, np.nan) if velocity is None else velocity
        values = np.concatenate([xyz, normalised(quat), velocity], axis=1)
        known = self.stamps[: self.size]
        if (stamps[1:] >= stamps[:-1]).all() and (not self.size or stamps[0] >= known[-1]):
            start = self.size - 1 if self.size and stamps[0] == known[-1] else self.size  # it replaces the last
        else:
            stamps, values = np.concatenate([known, stamps]), np.concatenate([self.values[: self.size], values])
            order = np.argsort(stamps, kind="stable")
            stamps, values = stamps[order], values[order]
            start = 0
        last = np.r_[stamps[1:] != stamps[:-1], True]
        self._put(start, stamps[last], values[last])

    def _put(self, start: int, stamps: np.ndarray, values: np.ndarray) -> None:
        """Write samples from position ``start`` on (the samples there and after are dropped)."""
        size = start + len(stamps)
        if size > len(self.stamps):
            capacity = max(2 * len(self.stamps), size, 16)
            grown_stamps, grown_values = np.empty(capacity, dtype=np.int64), np.empty((capacity, 10))
            grown_stamps[:start], grown_values[:start] = self.stamps[:start], self.values[:start]
            self.stamps, self.values = grown_stamps, grown_values
        self.stamps[start:size], self.values[start:size] = stamps, values
        self.size = size

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Stamps (sorted, one sample per stamp: the last received), positions, rotations,
        velocities (in the child frame; NaN unknown): views of the samples held."""
        values = self.values[: self.size]
        return self.stamps[: self.size], values[:, :3], values[:, 3:7], values[:, 7:]

    def last(self) -> int:
        """The stamp of the last sample (ns)."""
        return int(self.stamps[self.size - 1])

    def at(self, stamps: np.ndarray, child: str) -> tuple[np.ndarray, np.ndarray]:
        """Position and rotation of the child at each stamp (see the module docstring)."""
        known, xyz, quat, _ = self.arrays()
        if self.static:
            return np.repeat(xyz[-1:], len(stamps), axis=0), np.repeat(quat[-1:], len(stamps), axis=0)
        lower, upper, t, exact = self._between(stamps, child)
        if len(known) == 1:
            return xyz[lower], quat[lower]
        if exact.all():  # every stamp a sample's (nothing to interpolate)
            return xyz[upper], quat[upper]
        return _linear(xyz, lower, upper, t, exact), np.where(
            exact[:, None], quat[upper], slerp(quat[lower], quat[upper], t)
        )

    def velocity_at(self, stamps: np.ndarray, child: str) -> np.ndarray:
        """The child's velocity (its own axes; NaN unknown) at each stamp, interpolated linearly."""
        known, _, _, velocity = self.arrays()
        if self.static:
            return np.repeat(velocity[-1:], len(stamps), axis=0)
        lower, upper, t, exact = self._between(stamps, child)
        if len(known) == 1 or not self.moving:  # (NaN everywhere without odometry)
            return velocity[lower]
        return _linear(velocity, lower, upper, t, exact)

    def _between(self, stamps: np.ndarray, child: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Per stamp: the samples before and after it, its fraction of the way and whether it is
        the later sample's stamp; MissingTransform outside the samples."""
        known = self.stamps[: self.size]
        outside = (stamps < known[0]) | (stamps > known[-1])
        if outside.any():
            row = int(np.argmax(outside))
            raise MissingTransform(
                row,
                f"no transform {self.parent} <- {child} at {int(stamps[row])} ns "
                f"(known from {int(known[0])} to {int(known[-1])} ns)",
            )
        upper = np.clip(np.searchsorted(known, stamps, side="left"), 1, max(len(known) - 1, 1))
        lower = upper - 1
        if len(known) == 1:  # (the stamps are that sample's)
            return lower, lower, np.ones(len(stamps)), np.ones(len(stamps), dtype=bool)
        span = (known[upper] - known[lower]).astype(np.float64)
        t = np.clip((stamps - known[lower]) / span, 0.0, 1.0)
        exact = stamps == known[upper]
        return lower, upper, np.where(exact, 1.0, t), exact


def _linear(values: np.ndarray, lower: np.ndarray, upper: np.ndarray, t: np.ndarray, exact: np.ndarray) -> np.ndarray:
    """Samples' ``values`` interpolated linearly between ``lower`` and ``upper`` at fractions ``t``
    (the ``upper`` sample's values exactly where ``exact``)."""
    between = values[lower] + t[:, None] * (values[upper] - values[lower])
    return np.where(exact[:, None], values[upper], between)


class TfBuffer:
    """Frame links received so far; :meth:`lookup` composes them along a chain at given stamps."""

    def __init__(self) -> None:
        self.links: dict[str, _Link] = {}
        self._last: tuple | None = None
        """The last lookup: its frames, stamps and result (until links are added)."""

    def add(self, links: Transforms, static: bool = False) -> None:
        """Add the samples of ``links`` (``static``: they hold at every stamp)."""
        if not len(links):
            return
        self._last = None
        for child in dict.fromkeys(links.child.tolist()):
            rows = np.flatnonzero(links.child == child)
            parent = str(links.parent[rows[-1]])
            rows = rows[links.parent[rows] == parent]
            link = self.links.get(child)
            if link is None or link.parent != parent or link.static != static:
                link = self.links[child] = _Link(parent, static)
            velocity = None if links.velocity is None else links.velocity[rows]
            link.add(links.stamp[rows], links.xyz[rows], links.quat[rows], velocity)

    def chain(self, frame: str, target: str) -> list[str] | None:
        """The child frames whose links lead from ``frame`` up to ``target`` (empty when they are
        the same frame), or None when ``frame`` does not reach ``target``."""
        path: list[str] = []
        while frame != target:
            link = self.links.get(frame)
            if link is None or len(path) >= MAX_CHAIN:
                return None
            path.append(frame)
            frame = link.parent
        return path

    def latest(self, frame: str, target: str) -> int | None:
        """The last stamp (ns) up to which ``frame``'s chain to ``target`` is known (None: no chain;
        a chain of static links only is known at every stamp: the maximum int64)."""
        path = self.chain(frame, target)
        if path is None:
            return None
        ends = [self.links[c].last() for c in path if not self.links[c].static]
        return int(min(ends)) if ends else np.iinfo(np.int64).max

    def lookup(self, frame: str, target: str, stamps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Position (n, 3) and rotation (n, 4) of ``frame`` in ``target`` at each stamp (ns);
        MissingTransform when there is no chain or a link is unknown at a stamp. The same lookup
        again (the boxes of a frame in the ego's frame, then the ego, at the same stamps) gives
        the same arrays, not computed again: callers do not modify them."""
        stamps = np.asarray(stamps, dtype=np.int64)
        last = self._last
        if last is not None and last[:2] == (frame, target) and np.array_equal(last[2], stamps):
            return last[3]
        path = self.chain(frame, target)
        if path is None:
            raise MissingTransform(0, f"no transform chain from frame {frame!r} to {target!r}")
        xyz = np.zeros((len(stamps), 3))
        quat = np.tile([0.0, 0.0, 0.0, 1.0], (len(stamps), 1))
        for child in path:
            link_xyz, link_quat = self.links[child].at(stamps, child)
            xyz = quat_rotate(link_quat, xyz) + link_xyz
            quat = quat_multiply(link_quat, quat)
        self._last = (frame, target, stamps, (xyz, quat))
        return xyz, quat

    def velocity(self, frame: str, target: str, stamps: np.ndarray, rotation: np.ndarray) -> np.ndarray:
        """The velocity (n, 3, m/s) of ``frame``'s origin in ``target``'s axes at each stamp: its own
        link's velocity (an odometry twist, in ``frame``'s axes) turned by ``rotation`` (``frame``
        in ``target``, from :meth:`lookup`); NaN where its link gives none. The links above it are
        taken as still (an odometry frame's drift is not added)."""
        link = self.links.get(frame)
        if link is None or frame == target or not link.moving:
            return np.full((len(stamps), 3), np.nan)
        return quat_rotate(rotation, link.velocity_at(np.asarray(stamps, dtype=np.int64), frame))
