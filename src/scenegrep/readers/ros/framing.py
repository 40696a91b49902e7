"""Messages to frames, incrementally: batches of raw messages in, chunks of completed frames out.

:class:`FrameBuilder` is the one code path of the bag reader: :meth:`FrameBuilder.feed` takes a
batch of :class:`RawMessage` (in arrival order) and returns a :class:`LabelTrace` of the frames
that batch completed (None if none); :meth:`FrameBuilder.finish` returns the frames left at
the end of input. Fed one message at a time, each chunk is one frame as soon as it is
complete; the offline reader feeds large batches and concatenates the chunks.

**Frames.** On a frame topic (``frame_topic``; by default the first box topic met), every
message of that topic is a frame at its header stamp, holding its boxes and, of every other
box topic, the latest message stamped after the previous frame and at or before this one. At
a rate (``rate`` Hz), frame k covers header stamps ``[origin + k/rate, origin + (k+1)/rate)``
(origin: the first box message's stamp), is stamped at its start and holds the latest message
of each box topic in it; windows without messages are frames too (the ego alone).

**Completion.** A frame-topic frame is complete when its message arrives; a rate frame when a
box message stamped past its end arrives; every frame at the end of input. A complete frame
is emitted once the transforms it needs are known at its stamps (the ego's and every box
frame's chain to the map frame has a sample at or after them), so a ``/tf`` message that
arrives after the boxes it places is waited for; frames are emitted in stamp order. A box
message stamped at or before a frame already emitted arrives too late and is dropped (counted
in :attr:`FrameBuilder.late`).

**Objects.** A box's object is its id; the same id on two topics is one object, and when a
frame holds it twice the first row is kept (topics in the order their first batch arrived).
Objects are numbered in order of first appearance, so the chunks of a run concatenate to the
trace of one chunk.

**Map frame.** Boxes are moved into ``map_frame`` with the transform at their header stamp
(:class:`TfBuffer`: linear in translation, slerp in rotation); the ego (object ``ego``) is
``ego_frame``'s pose in the map frame at the frame's stamp, when ``ego_frame`` reaches the map
frame. Headings come from the yaw of the box in the map frame; velocities are the box's twist
turned into the map frame; the ego's velocity is its odometry twist where an odometry topic
gives its link (NaN from ``/tf``), its size ``ego_size`` (unknown without it: NaN, and the
trace attribute :data:`~scenegrep.model.trace.EGO_SIZE_UNKNOWN` says so). A missing transform at the
end of input is a :class:`UserError` naming the topic and the message's log time.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...errors import UserError
from ...model import BoxTable, ImageLayer, LabelTrace, ObjectTable, SampleTable, StateTable, TraceSource
from ...model.geometry import heading_from_yaw
from ...model.trace import EGO_SIZE_UNKNOWN
from .decoders import BOX_TYPES, LINK_TYPES, decode_batch, supported, type_key
from .messages import Boxes, DecodeError, ImageBoxes, RawMessage
from .msgdef import DefinitionError
from .options import BagOptions
from .transforms import MissingTransform, TfBuffer, quat_multiply, quat_rotate, yaw_of

EGO_ID = "ego"
"""The object id of the ego (the pose of ``ego_frame``)."""

STATIC_TOPIC = "/tf_static"
"""The topic whose links hold at every stamp."""

MAX_MESSAGE_BYTES = 256 << 20
"""The largest message decoded (a TrackedObjects message of 1,000 objects is about 500 kB)."""


@dataclass
class _Segment:
    """The boxes of one decoded batch of one topic, and its messages' stamps and log times."""

    topic: str
    boxes: Boxes
    stamps: np.ndarray
    log_times: np.ndarray
    alive: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.alive = np.ones(len(self.stamps), dtype=bool)


def _fail(topic: str, log_time: int, reason: str) -> UserError:
    return UserError(f"topic {topic}, message at log time {log_time} ns: {reason}")


class FrameBuilder:
    """The incremental pipeline (see the module docstring)."""

    def __init__(
        self,
        options: BagOptions,
        name: str,
        source: TraceSource | None = None,
        note: Callable[[str], None] | None = None,
    ):
        self.options = options
        self.name = name
        self.source = source
        self.note = note or (lambda text: print(f"scenegrep: note: {text}", file=sys.stderr))
        self.tf = TfBuffer()
        self.frame_topic = options.frame_topic
        self.segments: list[_Segment] = []
        self.skipped: dict[str, str] = {}
        self.late = 0
        self.emitted = 0
        self.last_stamp: int | None = None
        self.origin: int | None = None
        self.newest = np.iinfo(np.int64).min

    # ------------------------------------------------------------------ input
    def feed(self, batch: Sequence[RawMessage]) -> LabelTrace | None:
        """Take a batch of messages; the frames it completed, or None."""
        by_topic: dict[str, list[RawMessage]] = {}
        for message in batch:
            by_topic.setdefault(message.topic, []).append(message)
        for topic, messages in by_topic.items():
            self._topic(topic, messages)
        return self._emit(final=False)

    def finish(self) -> LabelTrace | None:
        """The frames left at the end of input; notes unknown topics and late messages on stderr."""
        chunk = self._emit(final=True)
        if self.skipped:
            listed = ", ".join(f"{t} ({k})" for t, k in self.skipped.items())
            self.note(f"skipped topics of unsupported types: {listed}")
        if self.late:
            self.note(f"{self.late} box messages arrived after their frame was built and were dropped")
        return chunk

    def _topic(self, topic: str, messages: list[RawMessage]) -> None:
        first = messages[0]
        kind = type_key(first.schema_name)
        if not supported(first.schema_name, first.message_encoding):
            self.skipped.setdefault(topic, f"{first.schema_name}, {first.message_encoding or 'no'} encoding")
            return
        chosen = not self.options.topics or topic in self.options.topics
        if not chosen and not (kind == "tf2_msgs/TFMessage" and topic in ("/tf", STATIC_TOPIC)):
            return
        for m in messages:
            if len(m.data) > MAX_MESSAGE_BYTES:
                raise _fail(topic, m.log_time, f"a message of {len(m.data)} bytes (at most {MAX_MESSAGE_BYTES})")
            if (m.schema_name, m.message_encoding) != (first.schema_name, first.message_encoding):
                raise _fail(topic, m.log_time, f"type {m.schema_name} on a topic of type {first.schema_name}")
        try:
            decoded = decode_batch(messages)
        except DecodeError as exc:
            raise _fail(topic, messages[exc.message].log_time, exc.reason) from None
        except DefinitionError as exc:
            raise _fail(topic, first.log_time, f"schema {first.schema_name}: {exc}") from None
        except KeyError as exc:
            raise _fail(topic, first.log_time, f"schema {first.schema_name} has no field {exc.args[0]}") from None
        if kind in LINK_TYPES:
            self.tf.add(decoded, static=topic == STATIC_TOPIC)  # type: ignore[arg-type]
        elif kind in BOX_TYPES:
            self._boxes(topic, decoded, np.array([m.log_time for m in messages], dtype=np.int64))  # type: ignore[arg-type]

    def _boxes(self, topic: str, boxes: Boxes, log_times: np.ndarray) -> None:
        if self.frame_topic is None and self.options.rate is None:
            self.frame_topic = topic
        if self.origin is None and self.options.rate is not None:
            self.origin = int(boxes.message_stamps.min())
        segment = _Segment(topic, boxes, boxes.message_stamps, log_times)
        if self.last_stamp is not None:
            late = segment.stamps <= self.last_stamp
            if self.options.rate is not None:
                late = segment.stamps < self.last_stamp + self._period()
            self.late += int(late.sum())
            segment.alive &= ~late
        self.newest = max(self.newest, int(segment.stamps.max()))
        self.segments.append(segment)

    # ------------------------------------------------------------------ frames
    def _period(self) -> int:
        return round(1e9 / self.options.rate)  # type: ignore[operator]

    def _candidates(self, final: bool) -> np.ndarray:
        """Stamps of the complete frames not yet emitted, sorted."""
        if self.options.rate is None:
            stamps = [s.stamps[s.alive] for s in self.segments if s.topic == self.frame_topic]
            return np.unique(np.concatenate(stamps)) if stamps else np.empty(0, np.int64)
        if self.origin is None:
            return np.empty(0, np.int64)
        period = self._period()
        alive = [s.stamps[s.alive] for s in self.segments]
        pending = np.concatenate(alive) if alive else np.empty(0, np.int64)
        first = (self.last_stamp + period) if self.last_stamp is not None else None
        if first is None:
            if not len(pending):
                return np.empty(0, np.int64)
            first = self.origin + (int(pending.min()) - self.origin) // period * period
        if final:
            last = (
                self.origin + (int(pending.max()) - self.origin) // period * period if len(pending) else first - period
            )
        else:
            last = self.origin + (self.newest - self.origin) // period * period - period
        return np.arange(first, last + 1, period, dtype=np.int64) if last >= first else np.empty(0, np.int64)

    def _messages(self, stamps: np.ndarray) -> list[tuple[_Segment, np.ndarray, np.ndarray]]:
        """For frames at ``stamps``: per segment, the messages each frame takes and their frames."""
        previous = self.last_stamp if self.last_stamp is not None else np.iinfo(np.int64).min
        chosen = []
        for segment in self.segments:
            rows = np.flatnonzero(segment.alive)
            s = segment.stamps[rows]
            if self.options.rate is not None:
                frame = np.searchsorted(stamps, s, side="right") - 1
                keep = (frame >= 0) & (s < stamps[-1] + self._period())
            elif segment.topic == self.frame_topic:
                frame = np.searchsorted(stamps, s)
                keep = frame < len(stamps)
                keep[keep] &= stamps[frame[keep]] == s[keep]
            else:
                frame = np.searchsorted(stamps, s, side="left")
                keep = (frame < len(stamps)) & (s > previous)
            chosen.append((segment, rows[keep], frame[keep]))
        return [self._latest_per_frame(items) for items in _by_topic(chosen).values()]

    @staticmethod
    def _latest_per_frame(items: list[tuple[_Segment, np.ndarray, np.ndarray]]) -> list:
        """Of one topic's messages, the latest stamped (the last received on a tie) per frame."""
        stamps = np.concatenate([seg.stamps[rows] for seg, rows, _ in items])
        if not len(stamps):  # none of its messages falls in these frames (one message fed at a time)
            return items
        frames = np.concatenate([f for _, _, f in items])
        arrival = np.arange(len(stamps))
        order = np.lexsort((arrival, stamps, frames))
        last = np.r_[frames[order][1:] != frames[order][:-1], True]
        winner = np.zeros(len(stamps), dtype=bool)
        winner[order[last]] = True
        out, start = [], 0
        for seg, rows, f in items:
            take = winner[start : start + len(rows)]
            out.append((seg, rows[take], f[take]))
            start += len(rows)
        return out

    def _needed(self, picks: list) -> dict[str, int]:
        """The latest stamp at which the chosen boxes need a transform, by frame id (the map frame
        needs none)."""
        need: dict[str, int] = {}
        for seg, rows, _ in picks:
            if isinstance(seg.boxes, ImageBoxes):
                continue
            rows_of = np.isin(seg.boxes.message, rows)
            for frame_id in set(seg.boxes.frame_id[rows_of].tolist()):
                if frame_id != self.options.map_frame:
                    at = int(seg.boxes.stamp[rows_of][seg.boxes.frame_id[rows_of] == frame_id].max())
                    need[frame_id] = max(need.get(frame_id, at), at)
        return need

    def _ready(self, stamps: np.ndarray, final: bool) -> int:
        """How many of the candidate frames can be emitted now."""
        if final or not len(stamps):
            return len(stamps)
        ego = self.tf.latest(self.options.ego_frame, self.options.map_frame)
        ready = len(stamps) if ego is None else int(np.searchsorted(stamps, ego, side="right"))
        while ready:
            picks = [p for topic in self._messages(stamps[:ready]) for p in topic]
            need = self._needed(picks)
            if all((self.tf.latest(f, self.options.map_frame) or -1) >= at for f, at in need.items()):
                return ready
            ready -= 1
        return 0

    def _emit(self, final: bool) -> LabelTrace | None:
        stamps = self._candidates(final)
        stamps = stamps[: self._ready(stamps, final)]
        if not len(stamps):
            return None
        picks = [p for topic in self._messages(stamps) for p in topic]
        chunk = self._chunk(stamps, picks)
        self.last_stamp = int(stamps[-1])
        horizon = self.last_stamp + (self._period() - 1 if self.options.rate is not None else 0)
        for segment in self.segments:
            segment.alive &= segment.stamps > horizon
        self.segments = [s for s in self.segments if s.alive.any()]
        return chunk

    # ------------------------------------------------------------------ building
    def _chunk(self, stamps: np.ndarray, picks: list) -> LabelTrace:
        images = _image_layer([p for p in picks if isinstance(p[0].boxes, ImageBoxes)])
        parts = []
        for seg, rows, frames in picks:
            if isinstance(seg.boxes, ImageBoxes):
                continue
            frame_of = np.full(len(seg.stamps), -1)
            frame_of[rows] = frames
            taken = seg.boxes.take(frame_of[seg.boxes.message] >= 0)
            parts.append((seg, taken, frame_of[taken.message]))
        ids, categories, frame, columns = [], [], [], []
        for seg, boxes, frames in parts:
            if not len(boxes):
                continue
            xyz, quat = self._to_map(seg, boxes)
            velocity = quat_rotate(quat, boxes.velocity)
            ids.append(boxes.id)
            categories.append(boxes.category)
            frame.append(frames)
            columns.append(np.column_stack([xyz, heading_from_yaw(yaw_of(quat)), boxes.size, velocity[:, :2]]))
        ego = self._ego(stamps)
        if ego is not None:
            ids.append(np.full(len(stamps), EGO_ID, dtype=object))
            categories.append(np.full(len(stamps), EGO_ID, dtype=object))
            frame.append(np.arange(len(stamps)))
            columns.append(ego)
        return self._trace(stamps, ids, categories, frame, columns, ego is not None, images)

    def _to_map(self, seg: _Segment, boxes: Boxes) -> tuple[np.ndarray, np.ndarray]:
        xyz, quat = boxes.xyz.copy(), boxes.quat.copy()
        for frame_id in set(boxes.frame_id.tolist()):
            if frame_id == self.options.map_frame:
                continue
            rows = np.flatnonzero(boxes.frame_id == frame_id)
            # one lookup per distinct stamp (the objects of a message share theirs)
            stamps, each = np.unique(boxes.stamp[rows], return_inverse=True)
            try:
                t, q = self.tf.lookup(frame_id, self.options.map_frame, stamps)
            except MissingTransform:
                try:  # again per row, for the row the error names
                    self.tf.lookup(frame_id, self.options.map_frame, boxes.stamp[rows])
                except MissingTransform as exc:
                    raise _fail(seg.topic, int(seg.log_times[boxes.message[rows[exc.row]]]), exc.reason) from None
                raise
            t, q = t[each.ravel()], q[each.ravel()]
            xyz[rows] = quat_rotate(q, xyz[rows]) + t
            quat[rows] = quat_multiply(q, quat[rows])
        return xyz, quat

    def _ego(self, stamps: np.ndarray) -> np.ndarray | None:
        """Rows (x, y, z, heading, length, width, height, vx, vy) of the ego at ``stamps``, or None
        when the ego frame does not reach the map frame."""
        if self.tf.chain(self.options.ego_frame, self.options.map_frame) in (None, []):
            return None
        try:
            xyz, quat = self.tf.lookup(self.options.ego_frame, self.options.map_frame, stamps)
        except MissingTransform as exc:
            raise UserError(
                f"ego frame {self.options.ego_frame!r} at stamp {int(stamps[exc.row])} ns: {exc.reason}"
            ) from None
        size = np.tile(np.asarray(self.options.ego_size or (np.nan,) * 3, dtype=float), (len(stamps), 1))
        velocity = self.tf.velocity(self.options.ego_frame, self.options.map_frame, stamps, quat)
        return np.column_stack([xyz, heading_from_yaw(yaw_of(quat)), size, velocity[:, :2]])

    def _ego_size_note(self) -> dict[str, str]:
        """The :data:`EGO_SIZE_UNKNOWN` attribute when the options give no ego size."""
        if self.options.ego_size is not None:
            return {}
        return {
            EGO_SIZE_UNKNOWN: "/tf and odometry carry no size: give it with --ego-size LENGTH,WIDTH,HEIGHT when the "
            "bag is read (a dataset ingested it without: query the bag as a file)"
        }

    def _trace(self, stamps, ids, categories, frame, columns, has_ego: bool, images: ImageLayer | None) -> LabelTrace:
        if self.origin is None:
            self.origin = int(stamps[0])
        frame_all = np.concatenate(frame).astype(np.int64) if frame else np.empty(0, np.int64)
        by_frame = np.argsort(frame_all, kind="stable")
        frame_all = frame_all[by_frame]
        ids_all = (np.concatenate(ids) if ids else np.empty(0, dtype=object))[by_frame]
        values = (np.concatenate(columns) if columns else np.empty((0, 9)))[by_frame]
        category_all = (np.concatenate(categories) if categories else np.empty(0, dtype=object))[by_frame]
        # objects in the order they first appear (so chunks concatenate to the same table)
        inverse, index = _codes(ids_all)
        names = np.array(list(index), dtype=object)
        # codes are numbered in order of first appearance: a code is new where it passes every earlier one
        seen = np.maximum.accumulate(inverse) if len(inverse) else inverse
        first = np.flatnonzero(np.r_[len(inverse) > 0, inverse[1:] > seen[:-1]])
        category = category_all[first]
        key = frame_all * max(len(names), 1) + inverse
        order = np.argsort(key, kind="stable")
        unique_rows = order[np.r_[True, key[order][1:] != key[order][:-1]]] if len(key) else order
        x, y, z, heading, length, width, height, vx, vy = values[unique_rows].T
        states = StateTable.build(
            frame_all[unique_rows],
            inverse[unique_rows],
            x,
            y,
            heading,
            z=z,
            length=length,
            width=width,
            height=height,
            vx=vx,
            vy=vy,
        )
        chunk = LabelTrace.build(
            self.name,
            np.arange(self.emitted, self.emitted + len(stamps)),
            (stamps - self.origin) / 1e9,
            ObjectTable.build(names.tolist(), [str(c) for c in category]),
            states,
            ego=EGO_ID if has_ego else None,
            images=images,
            attributes={"dataset": "ros2-bag", "time_origin_ns": self.origin, **self._ego_size_note()},
            source=self.source,
        )
        self.emitted += len(stamps)
        return chunk


def _image_layer(picks: list[tuple[_Segment, np.ndarray, np.ndarray]]) -> ImageLayer | None:
    """The images of the chosen 2-D detection messages: one sample per message (its channel, its
    frame; no path, size unknown: 0), its boxes (no object: -1); samples in frame order."""
    if not picks:
        return None
    channels: dict[str, int] = {}
    classes: dict[str, int] = {}
    sample_frame, sample_channel, box_parts = [], [], []
    count = 0
    for seg, rows, frames in picks:
        boxes: ImageBoxes = seg.boxes  # type: ignore[assignment]
        order = np.argsort(frames, kind="stable")
        rows, frames = rows[order], frames[order]
        sample_of = np.full(len(seg.stamps), -1)
        sample_of[rows] = count + np.arange(len(rows))
        sample_frame.append(frames)
        sample_channel.append(
            np.array([channels.setdefault(str(c), len(channels)) for c in boxes.message_channels[rows]], dtype=np.int32)
        )
        taken = boxes.take(sample_of[boxes.message] >= 0)
        category = np.array([classes.setdefault(str(c), len(classes)) for c in taken.category], dtype=np.int32)
        box_parts.append((sample_of[taken.message], category, taken))
        count += len(rows)
    frame = np.concatenate(sample_frame)
    by_frame = np.argsort(frame, kind="stable")
    renumber = np.empty(count, dtype=np.int64)
    renumber[by_frame] = np.arange(count)
    sample = np.concatenate([renumber[p[0]] for p in box_parts]).astype(np.int32)
    order = np.argsort(sample, kind="stable")

    def column(name: str) -> np.ndarray:
        return np.concatenate([getattr(p[2], name) for p in box_parts]).astype(np.float64)[order]

    rotation = column("rotation")
    samples = SampleTable(
        tuple(channels),
        frame[by_frame].astype(np.int32),
        np.concatenate(sample_channel)[by_frame],
        np.full(count, "", dtype=object),
        np.zeros(count, dtype=np.int32),
        np.zeros(count, dtype=np.int32),
    )
    box_table = BoxTable(
        tuple(classes),
        sample[order],
        np.concatenate([p[1] for p in box_parts])[order],
        column("score").astype(np.float32),
        column("cx"),
        column("cy"),
        column("w"),
        column("h"),
        rotation,
        rotation != 0,
        np.full(len(sample), -1, dtype=np.int32),
    )
    return ImageLayer(samples, box_table)


def _by_topic(chosen: list[tuple[_Segment, np.ndarray, np.ndarray]]) -> dict[str, list]:
    out: dict[str, list] = {}
    for item in chosen:
        out.setdefault(item[0].topic, []).append(item)
    return out


def _codes(ids: np.ndarray) -> tuple[np.ndarray, dict[str, int]]:
    """Each of ``ids`` (strings) numbered in order of first appearance, and the numbering. The
    rows are grouped by string object first (a decoder repeats one object per distinct id, so
    the Python work is per distinct object, not per row)."""
    objects = np.fromiter(map(id, ids), dtype=np.int64, count=len(ids))
    _, first, inverse = np.unique(objects, return_index=True, return_inverse=True)
    index: dict[str, int] = {}
    code = np.empty(len(first), dtype=np.int64)
    for k in np.argsort(first, kind="stable").tolist():
        code[k] = index.setdefault(ids[first[k]], len(index))
    return code[inverse.ravel()], index


def frames(
    batches: Iterable[Sequence[RawMessage]],
    options: BagOptions,
    name: str,
    source: TraceSource | None = None,
    note: Callable[[str], None] | None = None,
) -> Iterator[LabelTrace]:
    """The chunks of frames completed by each batch of messages, then the rest at the end."""
    builder = FrameBuilder(options, name, source, note)
    for batch in batches:
        chunk = builder.feed(batch)
        if chunk is not None:
            yield chunk
    chunk = builder.finish()
    if chunk is not None:
        yield chunk
