"""The frames of a live MCAP stream, each as soon as it is complete (the online commands' input).

Messages come in batches (:meth:`.mcap_follow.MessageStream.batches`: one message at a time while the
reader keeps up with the writer, in bulk while it catches up). A message on a document channel
(:mod:`.mcap_documents`) is decoded at once into its frames. The other messages go to the bag
pipeline (:mod:`.ros.framing`, with the options in force, :func:`.ros.options.current`) a batch at a
time, so a frame comes out as soon as the pipeline has it complete: when its frame-topic message
has arrived and the transforms at its stamp are known; the frames it still holds come out when the
stream ends. The pipeline notes unsupported topics and late messages at the end, through ``note``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator

from ..model import LabelTrace, TraceSource
from .mcap_documents import document_frames
from .mcap_records import RawMessage


def live_chunks(
    batches: Iterable[list[RawMessage]], name: str, source: TraceSource, note: Callable[[str], None]
) -> Iterator[LabelTrace]:
    """Chunks of frames in the order they complete (see the module docstring)."""
    from .ros.framing import FrameBuilder
    from .ros.options import current

    builder = FrameBuilder(current(), name, source, note)
    for batch in batches:
        run: list[RawMessage] = []  # bag messages since the last document, fed together
        for message in [*batch, None]:
            document = None if message is None else document_frames(message)
            if message is not None and document is None:
                run.append(message)
                continue
            chunk = builder.feed(run) if run else None
            run = []
            yield from (c for c in (chunk, document) if c is not None)
    chunk = builder.finish()
    if chunk is not None:
        yield chunk
