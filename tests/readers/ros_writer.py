"""Test-only bag writing: faults the package's writer never makes (dropped and out-of-order
messages) and the ids the reader gives back (:mod:`scenegrep.writers.ros_bag` writes the bags)."""

from __future__ import annotations

import uuid
from pathlib import Path

from scenegrep.model import LabelTrace
from scenegrep.writers.ros_bag import BagMessage, tracked_messages, write_messages
from scenegrep.writers.ros_messages import object_uuid


def read_back_id(object_id: str) -> str:
    """The id the reader gives back for an object written with :func:`object_uuid`."""
    return str(uuid.UUID(bytes=object_uuid(object_id)))


def write_faulty(
    trace: LabelTrace, path: Path, origin_ns: int, drop: frozenset[int] = frozenset(), late_tf: bool = False
) -> None:
    """:func:`~scenegrep.writers.ros_bag.write_tracked` with faults: ``drop``, frame positions whose
    box message is not written; ``late_tf``, each frame's /tf message written after the next
    frame's boxes (out of order)."""
    messages: list[BagMessage] = []
    pending = None
    for f, (ego, boxes) in enumerate(tracked_messages(trace, origin_ns)):
        if not late_tf:
            messages.append(ego)
        if f not in drop:
            messages.append(boxes)
        if late_tf:
            messages += [pending] if pending is not None else []
            pending = ego
    write_messages(path, messages + ([pending] if pending is not None else []))
