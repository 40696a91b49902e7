"""Raw messages to decoded segments: the bag pipeline's decoding stage, before framing.

A :class:`Decoder` takes a batch's messages a run at a time (:meth:`Decoder.add`: the offline
reader gives a chunk's messages, the live reader a batch as it arrived) and decodes each topic's
messages of the run at once (:class:`.decoders.TopicBatch`), so a chunk is read while it is still
in memory and nothing refers to it afterwards. :meth:`Decoder.take` ends the batch: one
:class:`Segment` per topic, in the order the topics first appear in the batch. Only the topics
read are decoded (:meth:`BagOptions.topics`, and ``/tf`` and ``/tf_static`` always); a topic of an
unsupported type is a segment with nothing decoded (framing notes it).

**Faults** are :class:`UserError` texts naming the topic and a message's log time (:func:`fail`),
raised by :meth:`Decoder.take` for the first topic of the batch (in that order) with one: a
message over :data:`MAX_MESSAGE_BYTES` or of another type than the topic's first in the batch (the
first such message), else a message the decoder cannot read, a schema it cannot parse, or a field
the decoder needs that the schema lacks.

:func:`decoded_batches` cuts a stream of runs into batches of :data:`BATCH` messages (every
message counted, read or not) and yields each batch's segments: the offline reader's input to
:meth:`.framing.FrameBuilder.run`.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from operator import itemgetter

import numpy as np

from ...errors import UserError
from .decoders import TopicBatch, supported, type_key
from .messages import Boxes, DecodeError, ImageBoxes, RawMessage, Transforms
from .msgdef import DefinitionError
from .options import BagOptions

BATCH = 1024
"""Messages decoded together by the offline reader."""

MAX_MESSAGE_BYTES = 256 << 20
"""The largest message decoded (a TrackedObjects message of 1,000 objects is about 500 kB)."""

STATIC_TOPIC = "/tf_static"
"""The topic whose links hold at every stamp."""

_TF_TOPICS = ("/tf", STATIC_TOPIC)
_KIND = itemgetter(1, 4)  # a RawMessage's schema name and message encoding
_LOG_TIME = itemgetter(5)
_DATA = itemgetter(6)


@dataclass(frozen=True)
class Segment:
    """The messages of one topic in a batch: their ``log_times`` (ns, int64, in order) and what
    they decode to (``decoded``; None for a topic of an unsupported type, not decoded: its
    ``log_times`` then empty, as nothing reads them)."""

    topic: str
    schema_name: str
    message_encoding: str
    log_times: np.ndarray
    decoded: Boxes | ImageBoxes | Transforms | None


def fail(topic: str, log_time: int, reason: str) -> UserError:
    """The error of a message (its topic and log time)."""
    return UserError(f"topic {topic}, message at log time {log_time} ns: {reason}")


class _Topic:
    """One topic's messages in the batch so far: its first message, their log times, the first
    fault found before decoding (size or type), and its decoding (None: not read)."""

    def __init__(self, first: RawMessage, read: bool, capacity: int):
        self.first = first
        self.kind = _KIND(first)
        self.supported = supported(*self.kind)
        self.log_times: list[int] = []
        self.fault: UserError | None = None
        self.batch = TopicBatch(first, capacity) if self.supported and read else None

    def add(self, messages: list[RawMessage]) -> None:
        if self.batch is None or self.fault is not None:
            return
        self.log_times.extend(map(_LOG_TIME, messages))
        kinds = list(map(_KIND, messages))
        if max(map(len, map(_DATA, messages))) > MAX_MESSAGE_BYTES or kinds.count(self.kind) != len(kinds):
            for m in messages:  # the first bad message
                if len(m.data) > MAX_MESSAGE_BYTES:
                    self.fault = fail(
                        m.topic, m.log_time, f"a message of {len(m.data)} bytes (at most {MAX_MESSAGE_BYTES})"
                    )
                    return
                if _KIND(m) != self.kind:
                    self.fault = fail(m.topic, m.log_time, f"type {m.schema_name} on a topic of type {self.kind[0]}")
                    return
        self.batch.add(messages)

    def segment(self) -> Segment | None:
        """The topic's segment (None: a topic not read); UserError for its first fault."""
        first, topic = self.first, self.first.topic
        log_times = np.array(self.log_times, dtype=np.int64)
        if not self.supported:
            return Segment(topic, first.schema_name, first.message_encoding, log_times, None)
        if self.batch is None:
            return None
        if self.fault is not None:
            raise self.fault
        try:
            decoded = self.batch.result()
        except DecodeError as exc:
            raise fail(topic, self.log_times[exc.message], exc.reason) from None
        except DefinitionError as exc:
            raise fail(topic, first.log_time, f"schema {first.schema_name}: {exc}") from None
        except KeyError as exc:
            raise fail(topic, first.log_time, f"schema {first.schema_name} has no field {exc.args[0]}") from None
        return Segment(topic, first.schema_name, first.message_encoding, log_times, decoded)


class Decoder:
    """A batch's messages in, a run at a time; its segments out (see the module docstring).
    ``capacity``: the most messages a batch holds (None: as many as the first run of a topic)."""

    def __init__(self, options: BagOptions, capacity: int | None = None):
        self.options = options
        self.capacity = capacity
        self.topics: dict[str, _Topic] = {}
        self.count = 0

    def _reads(self, topic: str, schema_name: str) -> bool:
        """Whether a topic is read: chosen (every topic when none are), or a transform topic."""
        chosen = not self.options.topics or topic in self.options.topics
        return chosen or (type_key(schema_name) == "tf2_msgs/TFMessage" and topic in _TF_TOPICS)

    def add(self, messages: Sequence[RawMessage]) -> None:
        """Decode the next messages of the batch (in arrival order)."""
        by_topic: dict[str, list[RawMessage]] = {}
        for message in messages:
            by_topic.setdefault(message.topic, []).append(message)
        for topic, run in by_topic.items():
            state = self.topics.get(topic)
            if state is None:
                first = run[0]
                capacity = len(run) if self.capacity is None else max(self.capacity - self.count, len(run))
                state = self.topics[topic] = _Topic(first, self._reads(topic, first.schema_name), capacity)
            state.add(run)
        self.count += len(messages)

    def take(self) -> list[Segment]:
        """The batch's segments, and a new batch begun; UserError for the batch's first fault."""
        topics, self.topics, self.count = self.topics, {}, 0
        return [s for state in topics.values() if (s := state.segment()) is not None]


def segments(messages: Sequence[RawMessage], options: BagOptions) -> list[Segment]:
    """The segments of one batch of messages (:class:`Decoder`)."""
    decoder = Decoder(options)
    decoder.add(messages)
    return decoder.take()


def decoded_batches(
    runs: Iterable[Sequence[RawMessage]], options: BagOptions, size: int = BATCH
) -> Iterator[list[Segment]]:
    """The segments of consecutive batches of ``size`` messages of ``runs`` (the last may hold
    fewer), each run decoded as it comes."""
    decoder = Decoder(options, size)
    for run in runs:
        while run:
            room = size - decoder.count
            decoder.add(run[:room])
            run = run[room:]
            if decoder.count == size:
                yield decoder.take()
    if decoder.count:
        yield decoder.take()
