"""MCAP messages that carry the JSON documents scenegrep already reads.

A channel whose message encoding is ``json`` carries, by its schema name:

* ``scenegrep/Trace``: scenegrep JSON trace documents (:mod:`.trace_json`), usually one frame each;
* ``strem/Document``: STREM JSON v0.2.0 documents (:mod:`.strem_json`), image boxes for SpRE.

:func:`document_frames` decodes such a message into a trace of its frames (None for a message of
any other channel). A document that does not parse is a :class:`~scenegrep.errors.UserError` naming
the topic and the message's log time.
"""

from __future__ import annotations

from ..model import LabelTrace
from .mcap_records import RawMessage

TRACE_SCHEMA = "scenegrep/Trace"
STREM_SCHEMA = "strem/Document"


def document_frames(message: RawMessage) -> LabelTrace | None:
    """The frames of a document message, or None if ``message`` is not on a document channel."""
    if message.message_encoding != "json" or message.schema_name not in (TRACE_SCHEMA, STREM_SCHEMA):
        return None
    if message.schema_name == TRACE_SCHEMA:
        from .trace_json import decode
    else:
        from .strem_json import decode  # type: ignore[assignment]
    place = f"{message.topic} @ {message.log_time} ns"
    return decode(message.data, place, message.topic.strip("/").replace("/", "_") or "mcap")
