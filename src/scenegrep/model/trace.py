"""The label trace: frames x objects of labels, the one data model every query reads.

A :class:`LabelTrace` is a sequence of frames (a position 0..F-1, the dataset's
frame ``index`` used for printing, a ``time`` in seconds from the start of the
recording), the objects seen in it (:class:`ObjectTable`), their per-frame
kinematic states (:class:`StateTable`, a long table), optional behaviour label
sets aligned with the states (:class:`BehaviourLabels`), optional 2-D image
detections (:class:`ImageLayer`), free trace-level attributes (weather, time of
day, ...) and where its road map comes from (:class:`MapSource`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any
from collections.abc import Mapping

import numpy as np

from .behaviours import BehaviourLabels
from .images import ImageLayer, concatenate_layers
from .objects import ObjectTable
from .states import BLOCK, StateTable


EGO_SIZE_UNKNOWN = "ego_size_unknown"
"""Trace attribute of a reader whose data gives the ego's pose but not its size (a ROS bag's
``/tf`` or odometry): its value says why and how to give the size. The ego's length, width and
height are then NaN, and a query that needs the ego's extent is an error quoting it (never a
default size)."""

MAX_FRAMES = 10_000_000
"""The most frames a trace may have (about 11.5 days at 10 Hz): a frame count or range a file
states is checked against it before any array is sized by it."""


def checked_frame_count(n: int) -> int:
    """``n`` when it is a frame count a trace may have (0..:data:`MAX_FRAMES`); ValueError otherwise."""
    if not 0 <= n <= MAX_FRAMES:
        raise ValueError(f"{n} frames: a trace has 0 to {MAX_FRAMES} frames")
    return n


@dataclass(frozen=True)
class MapSource:
    """Where a trace's road map can be read: a file or directory path, its format name, and
    the map's key inside the file when one file holds several (a scenario id, say)."""

    path: str
    format: str
    key: str | None = None


@dataclass(frozen=True)
class TraceSource:
    """Where a trace was read from: a path (or ``<stdin>``) and the detected format name."""

    path: str
    format: str


@dataclass(frozen=True, eq=False)
class LabelTrace:
    """A labeled recording; see the module docstring. Build it with :meth:`build`."""

    name: str
    frame_index: np.ndarray
    frame_time: np.ndarray
    objects: ObjectTable
    states: StateTable
    lane_ids: tuple[str, ...] = ()
    behaviours: BehaviourLabels | None = None
    images: ImageLayer | None = None
    ego: str | None = None
    attributes: Mapping[str, Any] = field(default_factory=dict)
    source: TraceSource | None = None
    map_source: MapSource | None = None

    @classmethod
    def build(
        cls, name: str, frame_index: Any, frame_time: Any, objects: ObjectTable, states: StateTable, **optional: Any
    ) -> LabelTrace:
        """Make a trace from columns and check its invariants (:meth:`validate`).

        States (and the behaviour labels aligned with them) are put in (frame, object) order.
        """
        order = states.sort_order()
        if order is not None:
            states = states.take(order)
            if optional.get("behaviours") is not None:
                optional["behaviours"] = optional["behaviours"].take(order)
        trace = cls(
            name,
            np.ascontiguousarray(frame_index, dtype=np.int64),
            np.ascontiguousarray(frame_time, dtype=np.float64),
            objects,
            states,
            **optional,
        )
        trace._validate(ordered=order is None)
        return trace

    # ------------------------------------------------------------------ sizes
    @property
    def n_frames(self) -> int:
        return len(self.frame_index)

    @property
    def n_objects(self) -> int:
        return len(self.objects)

    @property
    def frame_period(self) -> float:
        """The frame period in seconds: the median step of the timestamps (0.1 for a one-frame trace)."""
        steps = np.diff(self.frame_time)
        return float(np.median(steps)) if len(steps) else 0.1

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame (0 for fewer than two frames)."""
        return float(self.frame_time[-1] - self.frame_time[0]) if self.n_frames > 1 else 0.0

    def validate(self) -> None:
        """Raise ValueError unless the tables are consistent (sorted, codes in range, aligned)."""
        self._validate(ordered=False)

    def _validate(self, ordered: bool) -> None:
        """:meth:`validate`; ``ordered``: the states were found in strictly increasing (frame,
        object) order (:meth:`StateTable.sort_order` gave None: with the codes in range, that is
        the order checked here, so it is not checked again)."""
        s = self.states
        if len(self.frame_time) != self.n_frames:
            raise ValueError("frame_index and frame_time differ in length")
        if len(s) and (s.frame.min() < 0 or s.frame.max() >= self.n_frames):
            raise ValueError("state frame out of range")
        if len(s) and (s.object.min() < 0 or s.object.max() >= self.n_objects):
            raise ValueError("state object out of range")
        if len(s) and (s.lane.min() < -1 or s.lane.max() >= len(self.lane_ids)):
            raise ValueError("state lane code out of range")
        if not ordered and not s.in_order(max(self.n_objects, 1)):
            raise ValueError("states must be sorted by (frame, object) without duplicates")
        if self.behaviours is not None and len(self.behaviours) != len(s):
            raise ValueError("behaviour labels must align with state rows")
        if self.ego is not None and self.ego not in self.objects.row_of():
            raise ValueError(f"ego {self.ego!r} is not an object of the trace")
        self._validate_fields()
        self._validate_values()
        if self.images is not None:
            self._validate_images(self.images)

    def _validate_fields(self) -> None:
        """Raise ValueError unless the trace-level fields have their types (a file may give any)."""
        sources = [f for f in (self.source, self.map_source) if f is not None]
        texts = [self.name, *self.lane_ids, *(v for f in sources for v in vars(f).values() if v is not None)]
        if not all(isinstance(t, str) for t in texts):
            raise ValueError("trace name, lane ids and source paths must be strings")
        if not isinstance(self.attributes, Mapping):
            raise ValueError(f"trace attributes must be a mapping, found {type(self.attributes).__name__}")

    def _validate_values(self) -> None:
        """Raise ValueError naming the first bad value: known frame times (NaN: unknown) must be
        finite and strictly increasing; positions and headings
        finite; no column infinite; sizes not negative (NaN: unknown)."""
        times = self.frame_time
        known = ~np.isnan(times)
        if np.isinf(times).any():
            raise ValueError(f"frame {self._frame_name(int(np.argmax(np.isinf(times))))}: time is infinite")
        steps = np.diff(times[known])
        if (steps <= 0).any():
            position = int(np.argmax(steps <= 0)) + 1
            raise ValueError(f"frame {self._frame_name(position)}: time does not increase (frame times must increase)")
        s = self.states
        for name in ("x", "y", "heading", "z", "length", "width", "height", "vx", "vy"):
            values = getattr(s, name)
            for start in range(0, len(values), BLOCK):  # (in blocks: small scratch arrays)
                block = values[start : start + BLOCK]
                bad = ~np.isfinite(block) if name in ("x", "y", "heading") else np.isinf(block)
                if name in ("length", "width", "height"):
                    bad |= block < 0
                if bad.any():
                    row = start + int(np.argmax(bad))
                    rule = _RULES[name]
                    raise ValueError(f"{self._state_name(row)}: {name} is {float(values[row])!r} (must be {rule})")

    def _frame_name(self, position: int) -> str:
        return f"{position} (index {self.frame_index[position]})"

    def _state_name(self, row: int) -> str:
        s = self.states
        return f"frame {self._frame_name(int(s.frame[row]))}, object {self.objects.id[s.object[row]]!r}"

    def _validate_images(self, images: ImageLayer) -> None:
        samples, boxes = images.samples, images.boxes
        if len(samples) and (samples.frame.min() < 0 or samples.frame.max() >= self.n_frames):
            raise ValueError("sample frame out of range")
        if np.any(np.diff(samples.frame) < 0) or np.any(np.diff(boxes.sample) < 0):
            raise ValueError("samples must be sorted by frame and boxes by sample")
        if len(boxes) and (boxes.sample.min() < 0 or boxes.sample.max() >= len(samples)):
            raise ValueError("box sample out of range")
        if len(boxes) and boxes.object.max() >= self.n_objects:
            raise ValueError("box object out of range")

    # ------------------------------------------------------------------ views
    def object_index(self, object_id: str) -> int:
        """Row of an object id; KeyError if absent."""
        return self.objects.row_of()[object_id]

    def present(self) -> np.ndarray:
        """Boolean matrix (frames, objects): True where the object is observed."""
        out = np.zeros((self.n_frames, self.n_objects), dtype=bool)
        out[self.states.frame, self.states.object] = True
        return out

    def dense(self, column: str) -> np.ndarray:
        """A state column as a (frames, objects) float matrix, NaN where unobserved."""
        out = np.full((self.n_frames, self.n_objects), np.nan)
        out[self.states.frame, self.states.object] = getattr(self.states, column)
        return out

    def lane_names(self) -> np.ndarray:
        """The lane id of every state row as strings ('' where unknown)."""
        vocab = np.array(list(self.lane_ids) + [""], dtype=object)
        return vocab[self.states.lane]

    def observed_frames(self) -> np.ndarray:
        """Number of frames in which each object is observed (length n_objects)."""
        return np.bincount(self.states.object, minlength=self.n_objects)

    # ------------------------------------------------------------------ slicing
    def slice_frames(self, start: int, stop: int) -> LabelTrace:
        """Frames at positions [start, stop); objects never observed there are dropped."""
        start, stop, _ = slice(start, stop).indices(self.n_frames)
        keep_frames = np.zeros(self.n_frames, dtype=bool)
        keep_frames[start:stop] = True
        return self._restrict(keep_frames, np.ones(self.n_objects, dtype=bool))

    def between(self, t_start: float, t_end: float) -> LabelTrace:
        """Frames whose time (s) lies in the closed interval [t_start, t_end]."""
        keep = (self.frame_time >= t_start) & (self.frame_time <= t_end)
        return self._restrict(keep, np.ones(self.n_objects, dtype=bool))

    def select_frames(self, keep: np.ndarray) -> LabelTrace:
        """Only the frames where the boolean array ``keep`` (one per frame) is True; every object kept."""
        return self._restrict(np.asarray(keep, dtype=bool), np.ones(self.n_objects, dtype=bool), drop_unobserved=False)

    def select_objects(self, object_ids: list[str] | tuple[str, ...]) -> LabelTrace:
        """Only the given objects (all frames kept); KeyError for an unknown id."""
        rows = self.objects.row_of()
        keep = np.zeros(self.n_objects, dtype=bool)
        keep[[rows[i] for i in object_ids]] = True
        return self._restrict(np.ones(self.n_frames, dtype=bool), keep, drop_unobserved=False)

    def _restrict(self, keep_frames: np.ndarray, keep_objects: np.ndarray, drop_unobserved: bool = True) -> LabelTrace:
        state_keep = keep_frames[self.states.frame] & keep_objects[self.states.object]
        images_keep = None
        if self.images is not None:
            images_keep = keep_frames[self.images.samples.frame]
            box_objects = self.images.boxes.object
            box_rows = images_keep[self.images.boxes.sample] & (box_objects >= 0)
            seen_in_boxes = np.bincount(box_objects[box_rows], minlength=self.n_objects) > 0
        else:
            seen_in_boxes = np.zeros(self.n_objects, dtype=bool)
        if drop_unobserved:
            seen = np.bincount(self.states.object[state_keep], minlength=self.n_objects) > 0
            keep_objects = keep_objects & (seen | seen_in_boxes)
        state_keep &= keep_objects[self.states.object]
        frame_map = np.cumsum(keep_frames) - 1
        object_map = np.where(keep_objects, np.cumsum(keep_objects) - 1, -1)
        states = self.states.take(state_keep)
        states = replace(
            states, frame=frame_map[states.frame].astype(np.int32), object=object_map[states.object].astype(np.int32)
        )
        objects = self.objects.take(keep_objects)
        ego = self.ego if self.ego in set(objects.id.tolist()) else None
        images = None if self.images is None else self.images.keep_samples(images_keep, frame_map, object_map)
        behaviours = None if self.behaviours is None else self.behaviours.take(state_keep)
        return replace(
            self,
            frame_index=self.frame_index[keep_frames],
            frame_time=self.frame_time[keep_frames],
            objects=objects,
            states=states,
            behaviours=behaviours,
            images=images,
            ego=ego,
        )

    # ------------------------------------------------------------------ comparison
    def equals(self, other: object) -> bool:
        """Equality of every table and field (NaN equals NaN)."""
        if not isinstance(other, LabelTrace):
            return False
        simple = ("name", "lane_ids", "ego", "source", "map_source")
        if any(getattr(self, f) != getattr(other, f) for f in simple):
            return False
        if dict(self.attributes) != dict(other.attributes):
            return False
        if not (
            np.array_equal(self.frame_index, other.frame_index) and np.array_equal(self.frame_time, other.frame_time)
        ):
            return False
        if not (self.objects.equals(other.objects) and self.states.equals(other.states)):
            return False
        return _optional_equal(self.behaviours, other.behaviours) and _optional_equal(self.images, other.images)


_RULES = {
    "x": "finite",
    "y": "finite",
    "heading": "finite",
    "z": "finite or unknown",
    "vx": "finite or unknown",
    "vy": "finite or unknown",
    "length": "finite, not negative, or unknown",
    "width": "finite, not negative, or unknown",
    "height": "finite, not negative, or unknown",
}
"""What each state column may hold (NaN means unknown), for :meth:`LabelTrace.validate`'s messages."""


def _optional_equal(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return bool(a.equals(b))


def concatenate(traces: list[LabelTrace]) -> LabelTrace:
    """The frames of ``traces`` one after the other (e.g. chunks of a stream); objects with the same
    id are the same object. Name, attributes and map come from the first trace, the ego from the
    first trace that has one (a stream's chunks before its ego appears have none); behaviour
    labels are kept if every trace has them; image layers are joined (:func:`concatenate_layers`)."""
    ids: dict[str, int] = {}
    categories: list[str] = []
    attributes: list[dict[str, Any]] = []
    lanes: dict[str, int] = {}
    parts = []
    image_parts = []
    offset = 0
    for trace in traces:
        object_map = np.array([ids.setdefault(str(i), len(ids)) for i in trace.objects.id], dtype=np.int32)
        image_parts.append((trace.images, offset, object_map))
        for row in np.flatnonzero(object_map >= len(categories)):
            categories.append(str(trace.objects.category[row]))
            attributes.append(dict(trace.objects.attributes[row]))
        lane_map = np.array([lanes.setdefault(name, len(lanes)) for name in trace.lane_ids] + [-1], dtype=np.int32)
        states = trace.states
        parts.append(
            replace(
                states,
                frame=(states.frame + offset).astype(np.int32),
                object=object_map[states.object],
                lane=lane_map[states.lane],
            )
        )
        offset += trace.n_frames
    states = StateTable(**{name: np.concatenate([p.columns()[name] for p in parts]) for name in parts[0].columns()})
    labelled = [t.behaviours for t in traces if t.behaviours is not None]
    behaviours = _concatenate_labels(labelled) if len(labelled) == len(traces) else None
    first = traces[0]
    return LabelTrace.build(
        first.name,
        np.concatenate([t.frame_index for t in traces]),
        np.concatenate([t.frame_time for t in traces]),
        ObjectTable.build(list(ids), categories, attributes),
        states,
        lane_ids=tuple(lanes),
        behaviours=behaviours,
        images=concatenate_layers(image_parts),
        ego=next((t.ego for t in traces if t.ego is not None), None),
        attributes=first.attributes,
        source=first.source,
        map_source=first.map_source,
    )


def _concatenate_labels(parts: list[BehaviourLabels]) -> BehaviourLabels:
    """Behaviour labels stacked row-wise over the union of their vocabularies (confidences dropped
    unless every part has them)."""
    vocabulary = list(dict.fromkeys(name for part in parts for name in part.vocabulary))
    column = {name: k for k, name in enumerate(vocabulary)}
    member = np.zeros((sum(len(p.member) for p in parts), len(vocabulary)), dtype=bool)
    scored = all(p.confidence is not None for p in parts)
    confidence = np.full(member.shape, np.nan, dtype=np.float32) if scored else None
    row = 0
    for part in parts:
        cols = [column[name] for name in part.vocabulary]
        member[row : row + len(part.member), cols] = part.member
        if confidence is not None:
            confidence[row : row + len(part.member), cols] = part.confidence
        row += len(part.member)
    return BehaviourLabels(tuple(vocabulary), member, confidence)
