"""The working environment of a SpRE over a label trace: its samples and their regions.

Two spaces (seed 004 §2.1, "image space" and "top-down space"):

- ``image``: the trace's 2-D detections. A sample is one camera channel's image of a
  frame (kept channels only); its regions are that image's boxes in pixels; the space
  bounds (for complements) are the image, [0, width] x [0, height].
- ``topdown``: the trace's object states. Each frame is one sample; each observed
  object is an oriented box in metres (centre x, y, heading, length, width; a point when
  the size is unknown); the ego is the trace's ego object; the bounds are the frame's
  objects' extent grown by a kilometre. A trace whose ego's size is unknown
  (:data:`~scenegrep.model.trace.EGO_SIZE_UNKNOWN`, a bag's ego) keeps the ego as a point for
  its centre and heading, but a formula that reads the ego region's extent (areas, widths,
  gaps, IoU, intersections, complements, interiors, closures) is an error
  (:attr:`Space.ego_extent_unknown`), not an answer about a point.

A formula is evaluated on every sample on its own; a frame satisfies it when one of its
samples does (a frame without samples satisfies nothing).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
from ..lazy import lazy_import

from ..errors import UserError
from ..model import LabelTrace, SampleTable
from ..model.geometry import box_corners
from ..model.taxonomy import kind_of
from ..model.trace import EGO_SIZE_UNKNOWN
from . import syntax as s
from .regions import Regions

shapely = lazy_import("shapely")

TOPDOWN_MARGIN_M = 1000.0
UNKNOWN_IMAGE_SIZE = 1e7
"""Bound (pixels) used for images whose size the stream does not state."""


@dataclass(frozen=True, eq=False)
class Space:
    """Samples and regions of one trace; see the module docstring. Region rows are sorted by sample."""

    kind: str
    n_frames: int
    sample_frame: np.ndarray
    bounds: np.ndarray
    region_sample: np.ndarray
    categories: tuple[str, ...]
    category: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    width: np.ndarray
    height: np.ndarray
    rotation: np.ndarray
    oriented: np.ndarray
    score: np.ndarray
    object: np.ndarray
    z: np.ndarray
    speed: np.ndarray
    object_ids: np.ndarray
    object_attributes: np.ndarray
    ego: int
    match_kinds: bool
    ego_extent_unknown: str | None = None
    """Why the ego's extent is unknown (None: known, or no ego): reading it is an error."""

    @property
    def n_samples(self) -> int:
        return len(self.sample_frame)

    @cached_property
    def universe(self) -> np.ndarray:
        """One box geometry per sample: the space bounds used for complements."""
        return shapely.box(*self.bounds.T)

    def _corners(self, rows: np.ndarray) -> np.ndarray:
        """Corners (n, 4, 2) of the given rows' boxes."""
        cx, cy, w, h, rot = (a[rows] for a in (self.cx, self.cy, self.width, self.height, self.rotation))
        if self.kind == "topdown":
            return box_corners(cx, cy, rot, h, w)
        c, sn = np.cos(rot)[:, None], np.sin(rot)[:, None]
        dx = np.stack([-w, w, w, -w], axis=1) / 2
        dy = np.stack([-h, -h, h, h], axis=1) / 2
        return np.stack([cx[:, None] + c * dx - sn * dy, cy[:, None] + sn * dx + c * dy], axis=2)

    @cached_property
    def _polygons(self) -> np.ndarray | None:
        """Polygons of all boxes, or None when every box is axis-aligned."""
        if not self.oriented.any():
            return None
        return shapely.polygons(self._corners(np.arange(len(self.cx))))

    @cached_property
    def _bounds(self) -> np.ndarray:
        """(x0, y0, x1, y1) of every box: from its size when axis-aligned, from its corners otherwise."""
        bounds = np.stack(
            [self.cx - self.width / 2, self.cy - self.height / 2, self.cx + self.width / 2, self.cy + self.height / 2],
            axis=1,
        )
        rotated = np.flatnonzero(self.oriented)
        if len(rotated):
            corners = self._corners(rotated)
            bounds[rotated] = np.stack(
                [corners[..., 0].min(1), corners[..., 1].min(1), corners[..., 0].max(1), corners[..., 1].max(1)], axis=1
            )
        return bounds

    def regions(self, rows: np.ndarray, ctx: np.ndarray) -> Regions:
        """The regions of the given region rows, each in the given context row."""
        x0, y0, x1, y1 = self._bounds[rows].T
        shape = None if self._polygons is None else self._polygons[rows]
        n = len(rows)
        return Regions(
            ctx,
            x0,
            y0,
            x1,
            y1,
            shape,
            np.zeros(n, bool),
            rows,
            self.width[rows],
            self.height[rows],
            self.score[rows],
            self.oriented[rows],
        )

    # ------------------------------------------------------------------ class atoms
    def matches(self, atom: s.ClassAtom) -> np.ndarray:
        """Which region rows belong to the atom's class and pass its filters."""
        return self._matches(atom)

    def _matches(self, atom: s.ClassAtom) -> np.ndarray:
        if atom.name == "*":
            mask = np.ones(len(self.category), bool)
        else:
            names = [
                k
                for k, c in enumerate(self.categories)
                if c == atom.name or (self.match_kinds and kind_of(c) == atom.name)
            ]
            mask = np.isin(self.category, names)
            if atom.name == "ego" and self.ego >= 0:
                mask |= self.object == self.ego
        for flt in atom.filters:
            mask &= self._filter(flt)
        return mask

    def _filter(self, flt: s.Filter) -> np.ndarray:
        if flt.key == "score":
            values = self.score.astype(float)
        elif flt.key == "id":
            values = np.where(self.object >= 0, self.object_ids[np.maximum(self.object, 0)], None)
        else:
            attrs = self.object_attributes
            values = np.array([attrs[o].get(flt.key) if o >= 0 else None for o in self.object], dtype=object)
        return _compare(values, flt.op, flt.value)

    def check_extent(self, regions: Regions, what: str) -> None:
        """UserError when ``what`` reads the extent of the ego's region and it is unknown."""
        if self.ego_extent_unknown is None or not len(regions):
            return
        src = regions.src[regions.src >= 0]
        if np.any(self.object[src] == self.ego):
            raise UserError(f"{what} reads the extent of the ego's region, and {self.ego_extent_unknown}")

    def samples_having(self, mask: np.ndarray) -> np.ndarray:
        """Per sample, whether it has a region of the row mask."""
        return np.bincount(self.region_sample[mask], minlength=self.n_samples) > 0

    @cached_property
    def sizes_nonnegative(self) -> bool:
        """Whether every box has a non-negative width and height (so none is an empty region)."""
        return bool(np.all(self.width >= 0) and np.all(self.height >= 0))

    def rows_by_sample(self, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(region rows, their samples) of a row mask, sorted by sample."""
        rows = np.flatnonzero(mask)
        return rows, self.region_sample[rows]

    def object_rows(self, obj: int) -> np.ndarray:
        """Region row of object ``obj`` in every sample (-1 where absent)."""
        out = np.full(self.n_samples, -1, dtype=np.int64)
        rows = np.flatnonzero(self.object == obj)
        out[self.region_sample[rows]] = rows
        return out


def _compare(values: np.ndarray, op: str, target: str | float) -> np.ndarray:
    """Element-wise ``values op target``; False where a value is missing or of another type."""
    out = np.zeros(len(values), bool)
    for i, value in enumerate(values.tolist()):
        if value is None:
            continue
        if isinstance(target, float):
            try:
                value = float(value)
            except (TypeError, ValueError):
                continue
        else:
            value = str(value)
        out[i] = {
            "=": value == target,
            "!=": value != target,
            "<": value < target,
            "<=": value <= target,
            ">": value > target,
            ">=": value >= target,
        }[op]
    return out


def channel_samples(samples: SampleTable, channels: tuple[str, ...]) -> np.ndarray:
    """Which samples (a boolean per row) come from one of ``channels``."""
    wanted = [k for k, name in enumerate(samples.channels) if name in channels]
    return np.isin(samples.channel, wanted)


def image_space(trace: LabelTrace, channels: tuple[str, ...] | None, match_kinds: bool) -> Space:
    """The image space of a trace's detections, keeping only ``channels`` (all when None)."""
    if trace.images is None:
        raise UserError(f"trace {trace.name!r} has no image detections; use the top-down space")
    samples, boxes = trace.images.samples, trace.images.boxes
    if channels is not None:
        keep = channel_samples(samples, channels)
        box_keep = keep[boxes.sample]
        samples = samples.take(keep)
        boxes = boxes.take(box_keep)
        boxes = replace(boxes, sample=(np.cumsum(keep) - 1)[boxes.sample].astype(np.int32))
    width = np.where(samples.image_width > 0, samples.image_width, UNKNOWN_IMAGE_SIZE).astype(float)
    height = np.where(samples.image_height > 0, samples.image_height, UNKNOWN_IMAGE_SIZE).astype(float)
    bounds = np.stack([np.zeros(len(samples)), np.zeros(len(samples)), width, height], axis=1)
    n = len(boxes)
    return Space(
        "image",
        trace.n_frames,
        samples.frame,
        bounds,
        boxes.sample,
        boxes.classes,
        boxes.category,
        boxes.cx,
        boxes.cy,
        boxes.w,
        boxes.h,
        boxes.rotation,
        boxes.oriented,
        boxes.score,
        boxes.object,
        np.full(n, np.nan),
        np.full(n, np.nan),
        trace.objects.id,
        trace.objects.attributes,
        -1 if trace.ego is None else trace.object_index(trace.ego),
        match_kinds,
    )


def topdown_space(trace: LabelTrace, match_kinds: bool) -> Space:
    """The top-down space of a trace's object states (one sample per frame)."""
    if len(trace.states) == 0 and trace.images is not None:
        raise UserError(f"trace {trace.name!r} has only image detections, no object states for the top-down space")
    st = trace.states
    n = len(st)
    length = np.nan_to_num(st.length, nan=0.0)
    width = np.nan_to_num(st.width, nan=0.0)
    frames = np.arange(trace.n_frames)
    lo_x = np.full(trace.n_frames, np.inf)
    lo_y, hi_x, hi_y = lo_x.copy(), -lo_x.copy(), -lo_x.copy()
    np.minimum.at(lo_x, st.frame, st.x)
    np.minimum.at(lo_y, st.frame, st.y)
    np.maximum.at(hi_x, st.frame, st.x)
    np.maximum.at(hi_y, st.frame, st.y)
    empty = ~np.isfinite(lo_x)
    lo_x[empty], lo_y[empty], hi_x[empty], hi_y[empty] = 0, 0, 0, 0
    bounds = np.stack(
        [lo_x - TOPDOWN_MARGIN_M, lo_y - TOPDOWN_MARGIN_M, hi_x + TOPDOWN_MARGIN_M, hi_y + TOPDOWN_MARGIN_M], axis=1
    )
    categories, codes = np.unique(trace.objects.category.astype(str), return_inverse=True)
    return Space(
        "topdown",
        trace.n_frames,
        frames,
        bounds,
        st.frame.astype(np.int64),
        tuple(categories.tolist()),
        codes[st.object],
        st.x,
        st.y,
        width,
        length,
        st.heading,
        np.ones(n, bool),
        np.ones(n),
        st.object.astype(np.int64),
        st.z,
        st.speed(),
        trace.objects.id,
        trace.objects.attributes,
        -1 if trace.ego is None else trace.object_index(trace.ego),
        match_kinds,
        _ego_extent_unknown(trace),
    )


def _ego_extent_unknown(trace: LabelTrace) -> str | None:
    """Why the ego's extent is unknown: the trace says its ego's size is unknown and the ego has
    no length or width at some frame (None otherwise)."""
    reason = trace.attributes.get(EGO_SIZE_UNKNOWN)
    if reason is None or trace.ego is None:
        return None
    st = trace.states
    ego = st.object == trace.object_index(trace.ego)
    if not np.any(ego & (np.isnan(st.length) | np.isnan(st.width))):
        return None
    return f"trace {trace.name!r} has no size for its ego {trace.ego!r}; {reason}"
