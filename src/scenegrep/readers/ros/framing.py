"""Messages to frames, incrementally: batches of decoded messages in, chunks of completed frames out.

:class:`FrameBuilder` is the one code path of the bag reader: a batch is a list of
:class:`~.segments.Segment` (a topic's messages decoded, :mod:`.segments`);
:meth:`FrameBuilder.feed` takes a batch of :class:`RawMessage` (in arrival order; the live
reader), decodes it and returns a :class:`LabelTrace` of the frames that batch completed (None
if none); :meth:`FrameBuilder.finish` returns the frames left at the end of input. Fed one
message at a time, each chunk is one frame as soon as it is complete; the offline reader feeds
batches decoded chunk by chunk (:func:`.segments.decoded_batches`) through
:meth:`FrameBuilder.run`, which makes one trace of all of them at the end (the chunks,
concatenated). Rows carry object ids, classes
and frame ids as integer codes (:class:`_Names`); the strings are looked at once per distinct
value of a batch, and the trace's objects are named once at the end.

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
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ...errors import UserError
from ...model import BoxTable, ImageLayer, LabelTrace, ObjectTable, SampleTable, StateTable, TraceSource
from ...model.geometry import heading_from_atan2, heading_from_yaw
from ...model.images import concatenate_layers
from ...model.states import FLOAT_COLUMNS, order_keys
from ...model.trace import EGO_SIZE_UNKNOWN, MAX_FRAMES
from .decoders import BOX_TYPES, LINK_TYPES, type_key
from .messages import Boxes, Coded, ImageBoxes, RawMessage
from .options import BagOptions
from ._place import place
from .columns import Column
from .segments import STATIC_TOPIC, Segment, segments
from .segments import fail as _fail
from .transforms import MissingTransform, TfBuffer, yaw_of

EGO_ID = "ego"
"""The object id of the ego (the pose of ``ego_frame``)."""


class _Names:
    """Strings numbered in order of first sight: the builder's codes of object ids, classes and
    frame ids (rows carry codes; a string is looked at once per distinct value of a batch)."""

    def __init__(self) -> None:
        self.index: dict[str, int] = {}
        self.names: list[str] = []

    def __len__(self) -> int:
        return len(self.names)

    def code(self, name: str) -> int:
        """The code of ``name`` (a new one the first time)."""
        code = self.index.get(name)
        if code is None:
            code = self.index[name] = len(self.names)
            self.names.append(name)
        return code

    def codes(self, column: np.ndarray | Coded) -> tuple[np.ndarray, np.ndarray]:
        """The code of every row of a string column (int32), and the codes of its names."""
        coded = column if isinstance(column, Coded) else Coded.of(column)
        names = coded.names.tolist()
        try:  # (every name known: looked up with no Python call per name)
            table = np.fromiter(map(self.index.__getitem__, names), dtype=np.int32, count=len(names))
        except KeyError:
            table = np.fromiter(map(self.code, names), dtype=np.int32, count=len(names))
        return table[coded.codes], table


@dataclass
class _Segment:
    """The boxes of one decoded batch of one topic, its messages' log times, and (3-D boxes) the
    builder's codes (int32) of every row's object id, class and frame id."""

    topic: str
    boxes: Boxes | ImageBoxes
    log_times: np.ndarray
    ids: np.ndarray | None = None
    classes: np.ndarray | None = None
    frames: np.ndarray | None = None
    objects: np.ndarray | None = None
    """The codes of the ids its rows may hold (each once)."""
    alive: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.alive = np.ones(len(self.stamps), dtype=bool)

    @property
    def stamps(self) -> np.ndarray:
        """The header stamp of every message (ns)."""
        return self.boxes.message_stamps

    def rows(self, messages: np.ndarray) -> np.ndarray | slice:
        """The rows of the boxes of ``messages`` (positions, each once): a boolean mask, or every
        row (a slice) when they are every message."""
        if len(messages) == len(self.stamps):
            return slice(None)
        chosen = np.zeros(len(self.stamps), dtype=bool)
        chosen[messages] = True
        return chosen[self.boxes.message]


class _Rows:
    """The rows of one trace as its frames are emitted (the offline run's whole bag, or one
    chunk of :meth:`FrameBuilder.feed`): the state columns, growing (:class:`.columns.Column`;
    rows in (frame, object) order, frames numbered from 0), the frames' ``times`` (s from the
    origin), their images, and the objects numbered in order of first
    appearance: ``number`` (per builder code of an object id; -1 not yet seen), ``objects`` (the
    codes in number order) and ``category`` (the class code of each at its first row)."""

    def __init__(self) -> None:
        self.frame = Column(np.int32)
        self.object = Column(np.int32)
        self.values = [Column(np.float64) for _ in FLOAT_COLUMNS]
        self.size = 0
        self.frames = 0
        self.number = np.empty(0, dtype=np.int32)
        self.objects: list[int] = []
        self.category: list[int] = []
        self.times: list[np.ndarray] = []
        self.images: list[tuple[ImageLayer | None, int]] = []
        self.has_ego = False

    def numbers(self, codes: int) -> np.ndarray:
        """``number``, grown to hold ``codes`` builder codes."""
        if len(self.number) < codes:
            self.number = np.concatenate([self.number, np.full(2 * codes - len(self.number), -1, dtype=np.int32)])
        return self.number


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
        self.ids, self.classes, self.frames = _Names(), _Names(), _Names()
        self.map_code = self.frames.code(options.map_frame)
        self._scratch = np.empty(0, dtype=np.int64)

    # ------------------------------------------------------------------ input
    def feed(self, batch: Sequence[RawMessage]) -> LabelTrace | None:
        """Take a batch of messages (decoded by :func:`.segments.segments`); the frames it
        completed, or None."""
        rows = _Rows()
        self._feed(segments(batch, self.options), rows)
        return self._trace(rows)

    def finish(self) -> LabelTrace | None:
        """The frames left at the end of input; notes unknown topics and late messages on stderr."""
        rows = _Rows()
        self._finish(rows)
        return self._trace(rows)

    def run(self, batches: Iterable[list[Segment]]) -> LabelTrace | None:
        """Feed the segments of every batch (:func:`.segments.decoded_batches`) and finish: all the
        frames as one trace (the chunks :meth:`feed` and :meth:`finish` would give, concatenated),
        or None when no frame was built. The frames' rows are written into one set of growing
        columns; the trace is made once, at the end."""
        rows = _Rows()
        for batch in batches:
            self._feed(batch, rows)
        self._finish(rows)
        return self._trace(rows)

    def _feed(self, batch: list[Segment], rows: _Rows) -> None:
        for segment in batch:
            self._segment(segment)
        self._emit(False, rows)

    def _finish(self, rows: _Rows) -> None:
        self._emit(True, rows)
        if self.skipped:
            listed = ", ".join(f"{t} ({k})" for t, k in self.skipped.items())
            self.note(f"skipped topics of unsupported types: {listed}")
        if self.late:
            self.note(f"{self.late} box messages arrived after their frame was built and were dropped")

    def _segment(self, segment: Segment) -> None:
        kind, decoded = type_key(segment.schema_name), segment.decoded
        if decoded is None:
            encoding = segment.message_encoding or "no"
            self.skipped.setdefault(segment.topic, f"{segment.schema_name}, {encoding} encoding")
        elif kind in LINK_TYPES:
            self.tf.add(decoded, static=segment.topic == STATIC_TOPIC)  # type: ignore[arg-type]
        elif kind in BOX_TYPES:
            self._boxes(segment.topic, decoded, segment.log_times)  # type: ignore[arg-type]

    def _boxes(self, topic: str, boxes: Boxes | ImageBoxes, log_times: np.ndarray) -> None:
        if self.frame_topic is None and self.options.rate is None:
            self.frame_topic = topic
        if self.origin is None and self.options.rate is not None:
            self.origin = int(boxes.message_stamps.min())
        segment = _Segment(topic, boxes, log_times)
        if isinstance(boxes, Boxes):
            segment.ids, objects = self.ids.codes(boxes.id)
            segment.objects = np.unique(objects)
            segment.classes, _ = self.classes.codes(boxes.category)
            segment.frames, _ = self.frames.codes(boxes.frame_id)
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
        if last < first:
            return np.empty(0, np.int64)
        count = (last - first) // period + 1
        if count > MAX_FRAMES:  # (a stamp far from the others: no array sized by it)
            raise UserError(
                f"--rate {self.options.rate:g}: box stamps from {first} to {last} ns make {count} frames "
                f"(a trace has 0 to {MAX_FRAMES})"
            )
        return np.arange(first, last + 1, period, dtype=np.int64)

    def _messages(self, stamps: np.ndarray) -> list[tuple[_Segment, np.ndarray, np.ndarray]]:
        """For frames at ``stamps``: per segment (by topic), the messages each frame takes and their frames."""
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
        return [p for items in _by_topic(chosen).values() for p in self._latest_per_frame(items)]

    @staticmethod
    def _latest_per_frame(items: list[tuple[_Segment, np.ndarray, np.ndarray]]) -> list:
        """Of one topic's messages, the latest stamped (the last received on a tie) per frame."""
        if len(items) == 1 and len(items[0][1]) < 2:
            return items
        stamps = np.concatenate([seg.stamps[rows] for seg, rows, _ in items])
        frames = np.concatenate([f for _, _, f in items])
        if (frames[1:] > frames[:-1]).all():  # one message per frame already
            return items
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

    def _needed(self, picks: list) -> dict[int, int]:
        """The latest stamp at which the chosen boxes need a transform, by frame id code (the map
        frame needs none)."""
        need: dict[int, int] = {}
        for seg, messages, _ in picks:
            if seg.frames is None:
                continue
            rows = seg.rows(messages)
            codes, stamps = seg.frames[rows], seg.boxes.stamp[rows]
            present = np.flatnonzero(np.bincount(codes, minlength=1))
            for code in present.tolist():
                if code != self.map_code:
                    at = int(stamps.max() if len(present) == 1 else stamps[codes == code].max())
                    need[code] = max(need.get(code, at), at)
        return need

    def _ready(self, stamps: np.ndarray, final: bool) -> tuple[int, list]:
        """How many of the candidate frames can be emitted now, and their picks (:meth:`_messages`)."""
        ready = len(stamps)
        if not final and len(stamps):
            ego = self.tf.latest(self.options.ego_frame, self.options.map_frame)
            ready = len(stamps) if ego is None else int(np.searchsorted(stamps, ego, side="right"))
        while ready:
            picks = self._messages(stamps[:ready])
            if final:
                return ready, picks
            need = self._needed(picks)
            names = self.frames.names
            if all((self.tf.latest(names[f], self.options.map_frame) or -1) >= at for f, at in need.items()):
                return ready, picks
            ready -= 1
        return 0, []

    def _emit(self, final: bool, rows: _Rows) -> None:
        """Add the frames now complete and ready to ``rows``."""
        stamps = self._candidates(final)
        ready, picks = self._ready(stamps, final)
        stamps = stamps[:ready]
        if not len(stamps):
            return
        self._part(stamps, picks, rows)
        self.last_stamp = int(stamps[-1])
        horizon = self.last_stamp + (self._period() - 1 if self.options.rate is not None else 0)
        for segment in self.segments:
            segment.alive &= segment.stamps > horizon
        self.segments = [s for s in self.segments if s.alive.any()]

    # ------------------------------------------------------------------ building
    def _part(self, stamps: np.ndarray, picks: list, out: _Rows) -> None:
        """Add the frames at ``stamps`` to ``out``: the rows of their picks (:meth:`_messages`)
        and the ego's, in (frame, object) order (in a frame, of the rows of one object the first
        in pick order, the ego last), objects numbered in order of first appearance."""
        if self.origin is None:
            self.origin = int(stamps[0])
        images = _image_layer([p for p in picks if p[0].frames is None])
        frame, ids, classes, objects, taken = [], [], [], [], []
        for seg, messages, frames in picks:
            if seg.frames is None:
                continue
            frame_of = np.full(len(seg.stamps), -1, dtype=np.int32)
            frame_of[messages] = frames
            rows = seg.rows(messages)
            if isinstance(rows, np.ndarray) and not rows.any():
                continue
            frame.append(frame_of[seg.boxes.message[rows]])
            ids.append(seg.ids[rows])  # type: ignore[index]
            classes.append(seg.classes[rows])  # type: ignore[index]
            objects.append(seg.objects)
            taken.append((seg, rows))
        has_ego = self.tf.chain(self.options.ego_frame, self.options.map_frame) not in (None, [])
        if has_ego:
            frame.append(np.arange(len(stamps), dtype=np.int32))
            ids.append(np.full(len(stamps), self.ids.code(EGO_ID), dtype=np.int32))
            classes.append(np.full(len(stamps), self.classes.code(EGO_ID), dtype=np.int32))
            objects.append(ids[-1][:1])
        frame_all, ids_all = (np.concatenate(c) if c else np.empty(0, np.int32) for c in (frame, ids))
        dest, kept_frames, kept_numbers = self._placement(frame_all, ids_all, classes, objects, out)
        start, stop = out.size, out.size + len(kept_frames)
        columns, cosine = [c.rows(start, stop) for c in out.values], np.empty(stop - start)
        offset = 0
        for (seg, rows), rows_frame in zip(taken, frame):  # (the boxes first: their errors come first)
            self._values(seg, rows, dest[offset : offset + len(rows_frame)], columns, cosine)
            offset += len(rows_frame)
        at = dest[offset:][dest[offset:] >= 0]  # (the ego's rows)
        heading = columns[FLOAT_COLUMNS.index("heading")]
        heading[at], cosine[at] = 0.0, 1.0
        heading_from_atan2(np.arctan2(heading, cosine, out=heading))
        if has_ego:
            for column, values in zip(columns, self._ego(stamps)):
                column[at] = values[dest[offset:] >= 0]
        np.add(kept_frames, out.frames, out=out.frame.rows(start, stop))
        out.object.rows(start, stop)[:] = kept_numbers
        out.size = stop
        out.images.append((images, out.frames))
        out.times.append((stamps - self.origin) / 1e9)
        out.frames += len(stamps)
        out.has_ego = out.has_ego or has_ego  # (frames emitted before the ego's chain was known have no ego row)

    def _placement(
        self, frame: np.ndarray, ids: np.ndarray, classes: list[np.ndarray], objects: list[np.ndarray], out: _Rows
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For rows of frames (positions among the new frames), object ids and classes (builder
        codes; ``classes`` in parts to concatenate), in pick order: the row of ``out``'s columns
        each is written to, relative to the rows it holds (-1: a repeat of its object in its
        frame, dropped), and the frame and object number of each row written, in order. The
        objects first seen here are numbered in ``out`` (in order of first appearance: by frame,
        then pick order)."""
        by_frame = None if (frame[1:] >= frame[:-1]).all() else np.argsort(frame, kind="stable")
        number = out.numbers(len(self.ids))
        candidates = np.unique(np.concatenate(objects)) if objects else ids
        new = candidates[number[candidates] < 0]
        if len(new):
            seen, first = self._first_rows(ids if by_frame is None else ids[by_frame], new)
            order = np.argsort(first, kind="stable")
            number[seen[order]] = np.arange(len(out.objects), len(out.objects) + len(seen), dtype=np.int32)
            out.objects += seen[order].tolist()
            first = first[order] if by_frame is None else by_frame[first[order]]
            out.category += np.concatenate(classes)[first].tolist()
        kept_frames = frame if by_frame is None else frame[by_frame]
        kept_numbers = number[ids if by_frame is None else ids[by_frame]]
        key = order_keys(kept_frames, kept_numbers, max(len(out.objects), 1))
        kept = by_frame
        if not (key[1:] > key[:-1]).all():  # an object twice in a frame, or objects out of order
            order = np.argsort(key, kind="stable")
            order = order[np.r_[True, key[order][1:] != key[order][:-1]]]
            kept = order if kept is None else kept[order]
            kept_frames, kept_numbers = kept_frames[order], kept_numbers[order]
        if kept is None:
            return np.arange(len(frame), dtype=np.int64), kept_frames, kept_numbers
        dest = np.full(len(frame), -1, dtype=np.int64)
        dest[kept] = np.arange(len(kept))
        return dest, kept_frames, kept_numbers

    def _first_rows(self, ids: np.ndarray, candidates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The codes among ``candidates`` that ``ids`` holds, and the first row of each (no sort:
        a minimum per code in a table of every code, reset only where ``candidates`` are)."""
        if len(self._scratch) < len(self.ids):
            self._scratch = np.empty(2 * len(self.ids), dtype=np.int64)
        self._scratch[candidates] = len(ids)
        np.minimum.at(self._scratch, ids, np.arange(len(ids)))
        first = self._scratch[candidates]
        present = first < len(ids)
        return candidates[present], first[present]

    def _values(
        self, seg: _Segment, rows: np.ndarray | slice, dest: np.ndarray, columns: list[np.ndarray], cosine: np.ndarray
    ) -> None:
        """Write the state values of ``rows`` of a segment's boxes into the state ``columns``
        (:data:`~scenegrep.model.states.FLOAT_COLUMNS`) at rows ``dest`` (-1: not written):
        each box moved into the map frame with the transform of its frame id at its stamp, its
        velocity turned by its rotation there (one pass of :func:`._place.place` over the boxes,
        with one transform per frame id and stamp); in place of the heading, the sine term of
        the rotation's yaw, its cosine term in ``cosine`` (the caller takes their atan2)."""
        boxes: Boxes = seg.boxes  # type: ignore[assignment]
        codes = seg.frames[rows]  # type: ignore[index]
        present = np.flatnonzero(np.bincount(codes, minlength=1)).tolist()
        each, shifts, turns, start = np.empty(len(codes), dtype=np.int64), [], [], 0
        for code in present:
            group = slice(None) if len(present) == 1 else np.flatnonzero(codes == code)
            if code == self.map_code:
                each[group] = -1
                continue
            shift, turn, at = self._transforms(seg, rows, group, code)
            each[group] = at + start
            shifts.append(shift)
            turns.append(turn)
            start += len(shift)
        shift = np.concatenate(shifts) if len(shifts) > 1 else shifts[0] if shifts else np.empty((0, 3))
        turn = np.concatenate(turns) if len(turns) > 1 else turns[0] if turns else np.empty((0, 4))
        xyz, quat, size, velocity = boxes.xyz[rows], boxes.quat[rows], boxes.size[rows], boxes.velocity[rows]
        place(xyz, quat, size, velocity, each, shift, turn, dest, columns, cosine)

    def _transforms(
        self, seg: _Segment, rows: np.ndarray | slice, group: np.ndarray | slice, code: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The translations (m, 3) and rotations (m, 4) of frame id ``code`` in the map frame at
        the distinct stamps of the boxes of ``group`` of ``rows``, and the position of each box's
        stamp among them (one lookup per distinct stamp; a stamp without a transform is a
        :class:`UserError` naming the first box's message without one)."""
        boxes: Boxes = seg.boxes  # type: ignore[assignment]
        stamps = boxes.stamp[rows][group]
        distinct, each = _distinct(stamps)
        frame_id = self.frames.names[code]
        try:
            t, q = self.tf.lookup(frame_id, self.options.map_frame, distinct)
        except MissingTransform:
            try:  # again per row, for the row the error names
                self.tf.lookup(frame_id, self.options.map_frame, stamps)
            except MissingTransform as exc:
                message = boxes.message[rows][group][exc.row]
                raise _fail(seg.topic, int(seg.log_times[message]), exc.reason) from None
            raise
        return t, q, each

    def _ego(self, stamps: np.ndarray) -> np.ndarray:
        """The (9, n) state values of the ego at ``stamps`` (rows :data:`FLOAT_COLUMNS`); the
        ego frame reaches the map frame."""
        try:
            xyz, quat = self.tf.lookup(self.options.ego_frame, self.options.map_frame, stamps)
        except MissingTransform as exc:
            raise UserError(
                f"ego frame {self.options.ego_frame!r} at stamp {int(stamps[exc.row])} ns: {exc.reason}"
            ) from None
        size = np.tile(np.asarray(self.options.ego_size or (np.nan,) * 3, dtype=float), (len(stamps), 1))
        velocity = self.tf.velocity(self.options.ego_frame, self.options.map_frame, stamps, quat)
        return np.column_stack([xyz, heading_from_yaw(yaw_of(quat)), size, velocity[:, :2]]).T

    def _ego_size_note(self) -> dict[str, str]:
        """The :data:`EGO_SIZE_UNKNOWN` attribute when the options give no ego size."""
        if self.options.ego_size is not None:
            return {}
        return {
            EGO_SIZE_UNKNOWN: "/tf and odometry carry no size: give it with --ego-size LENGTH,WIDTH,HEIGHT when the "
            "bag is read (a dataset ingested it without: query the bag as a file)"
        }

    def _trace(self, rows: _Rows) -> LabelTrace | None:
        """The trace of ``rows`` (None when they hold no frame), its first frame emitted as
        frame ``self.emitted``."""
        if not rows.frames:
            return None
        n = rows.size
        values = dict(zip(FLOAT_COLUMNS, (c.array(n) for c in rows.values)))
        states = StateTable.build(
            rows.frame.array(n), rows.object.array(n), lane=np.full(n, -1, dtype=np.int32), **values
        )
        names, class_names = self.ids.names, self.classes.names
        objects_table = ObjectTable.build(
            [names[k] for k in rows.objects], [str(class_names[c]) for c in rows.category]
        )
        images = (
            rows.images[0][0]
            if len(rows.images) == 1
            else concatenate_layers([(layer, o, np.empty(0, np.int32)) for layer, o in rows.images])
        )
        trace = LabelTrace.build(
            self.name,
            np.arange(self.emitted, self.emitted + rows.frames),
            np.concatenate(rows.times),
            objects_table,
            states,
            ego=EGO_ID if rows.has_ego else None,
            images=images,
            attributes={"dataset": "ros2-bag", "time_origin_ns": self.origin, **self._ego_size_note()},
            source=self.source,
        )
        self.emitted += rows.frames
        return trace


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


def _distinct(stamps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct values of ``stamps`` (sorted) and the position of each stamp among them; no
    sort when they are in order already (the rows of a batch are, message after message)."""
    if (stamps[1:] >= stamps[:-1]).all():
        new = np.r_[True, stamps[1:] != stamps[:-1]]
        return stamps[new], np.cumsum(new) - 1
    distinct, each = np.unique(stamps, return_inverse=True)
    return distinct, each.ravel()


def frames(
    batches: Iterable[list[Segment]],
    options: BagOptions,
    name: str,
    source: TraceSource | None = None,
    note: Callable[[str], None] | None = None,
) -> LabelTrace | None:
    """Every frame of the batches of segments as one trace, or None (:meth:`FrameBuilder.run`)."""
    return FrameBuilder(options, name, source, note).run(batches)
