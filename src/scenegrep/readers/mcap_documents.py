"""MCAP messages that carry the JSON documents scenegrep already reads, decoded into frames as they arrive.

A channel whose message encoding is ``json`` carries, by its schema name:

* ``scenegrep/Trace``: scenegrep JSON trace documents (:mod:`.trace_json`), usually one frame each;
* ``strem/Document``: STREM JSON v0.2.0 documents (:mod:`.strem_json`), image boxes for SpRE.

:func:`document_chunks` turns each such message into a trace of its frames as soon as it is read
(one message: one chunk for the online engines). Messages on other channels are skipped, each
topic named once through ``note``. A document that does not parse is a
:class:`~scenegrep.errors.UserError` naming the topic and the message's log time.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator

from ..model import LabelTrace
from .mcap_follow import RawMessage

TRACE_SCHEMA = "scenegrep/Trace"
STREM_SCHEMA = "strem/Document"


def _decoder(schema_name: str) -> Callable[[bytes, str, str], LabelTrace] | None:
    if schema_name == TRACE_SCHEMA:
        from .trace_json import decode

        return decode
    if schema_name == STREM_SCHEMA:
        from .strem_json import decode as decode_strem

        return decode_strem
    return None


def document_chunks(messages: Iterable[RawMessage], note: Callable[[str], None]) -> Iterator[LabelTrace]:
    """The frames of each document message, one trace per message, in the stream's order."""
    noted: set[str] = set()
    for message in messages:
        decode = _decoder(message.schema_name) if message.message_encoding == "json" else None
        if decode is None:
            if message.topic not in noted:
                noted.add(message.topic)
                kind = f"{message.schema_name or 'no schema'}, {message.message_encoding or 'no'} encoding"
                note(f"skipping topic {message.topic} ({kind}): not a {TRACE_SCHEMA} or {STREM_SCHEMA} JSON channel")
            continue
        place = f"{message.topic} @ {message.log_time} ns"
        yield decode(message.data, place, message.topic.strip("/").replace("/", "_") or "mcap")
