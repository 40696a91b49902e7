"""The records of the bag pipeline: raw messages in, decoded boxes and transforms out.

A :class:`RawMessage` is one message as a bag or MCAP stream holds it (the record
:mod:`scenegrep.readers.mcap_follow` yields while following a growing file, so the live
reader feeds this pipeline as is). Decoders turn a batch of
raw messages of one type into :class:`Boxes` (3-D objects, poses in their message's frame) or
:class:`Transforms` (time-stamped frame links, from ``/tf`` or an odometry topic). Times are
integer nanoseconds; lengths metres; quaternions (x, y, z, w). A column of strings (ids, classes,
frame ids) is an object array of ``str`` or a :class:`Coded` (codes into a table of names), so
the pipeline can work per distinct value, not per row.
"""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np

from ..mcap_records import RawMessage
from .factorize import by_object

__all__ = ["Boxes", "Coded", "DecodeError", "RawMessage", "Transforms"]


class DecodeError(ValueError):
    """A message of a batch that cannot be decoded: ``message`` is its position in the batch."""

    def __init__(self, message: int, reason: str):
        super().__init__(reason)
        self.message = message
        self.reason = reason


@dataclass(frozen=True)
class Coded:
    """A column of strings as integer ``codes`` (n,) into ``names`` (an object array of ``str``):
    row i is ``names[codes[i]]``. Names need not be distinct nor all used."""

    codes: np.ndarray
    names: np.ndarray

    @classmethod
    def of(cls, strings: np.ndarray) -> Coded:
        """The column of an object array of strings; the rows that hold one string object share a
        code (:func:`.factorize.by_object`), so the Python work is per distinct object, not per row
        (a decoder that repeats one object per distinct value gives each value one name)."""
        strings = np.asarray(strings, dtype=object)
        codes, first = by_object(strings)
        return cls(codes, strings[first])

    def __len__(self) -> int:
        return len(self.codes)

    def __getitem__(self, rows: np.ndarray | slice) -> Coded:
        """The rows selected by an index array, a boolean array or a slice."""
        return Coded(self.codes[rows], self.names)

    def strings(self) -> np.ndarray:
        """The column as an object array of strings."""
        return self.names[self.codes]


@dataclass(frozen=True)
class Boxes:
    """3-D boxes, one row per object observation: ``message`` (position of its message in the
    decoded batch), ``stamp`` (its header stamp, ns), ``frame_id`` (frame of its pose), ``id``
    (track id; '' when the message gives none), ``category`` (class name) (these three: object
    arrays of ``str`` or :class:`Coded`), position ``xyz``
    (n, 3), orientation ``quat`` (n, 4), box ``size`` (length, width, height; NaN unknown)
    and ``velocity`` (n, 3) in the box's own frame (x forward; NaN when not given);
    ``message_stamps``: the header stamp of every message of the batch, with objects or not."""

    message: np.ndarray
    stamp: np.ndarray
    frame_id: np.ndarray | Coded
    id: np.ndarray | Coded
    category: np.ndarray | Coded
    xyz: np.ndarray
    quat: np.ndarray
    size: np.ndarray
    velocity: np.ndarray
    message_stamps: np.ndarray

    ROWS = ("message", "stamp", "frame_id", "id", "category", "xyz", "quat", "size", "velocity")

    def __len__(self) -> int:
        return len(self.message)

    def take(self, rows: np.ndarray) -> Boxes:
        """The rows selected by an index or boolean array (``message_stamps`` kept whole)."""
        return Boxes(*(getattr(self, f)[rows] for f in self.ROWS), self.message_stamps)


@dataclass(frozen=True)
class Transforms:
    """Frame links: ``parent`` <- ``child`` at ``stamp`` (ns): the child's origin ``xyz`` (n, 3)
    and orientation ``quat`` (n, 4) in the parent frame, and where the message gives it (an
    odometry twist) the child's ``velocity`` (n, 3, m/s) in the child's own frame."""

    message: np.ndarray
    stamp: np.ndarray
    parent: np.ndarray
    child: np.ndarray
    xyz: np.ndarray
    quat: np.ndarray
    velocity: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.message)


@dataclass(frozen=True)
class ImageBoxes:
    """2-D detections, one row per box: ``message`` (position in the batch), ``category``,
    ``score``, centre ``cx``/``cy``, size ``w``/``h`` (pixels) and ``rotation`` (rad);
    per message of the batch: ``message_stamps`` (ns) and ``message_channels`` (its camera's
    frame id, else its topic), so a message without detections is still an image."""

    message: np.ndarray
    category: np.ndarray
    score: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    w: np.ndarray
    h: np.ndarray
    rotation: np.ndarray
    message_stamps: np.ndarray
    message_channels: np.ndarray

    ROWS = ("message", "category", "score", "cx", "cy", "w", "h", "rotation")

    def __len__(self) -> int:
        return len(self.message)

    def take(self, rows: np.ndarray) -> ImageBoxes:
        """The rows selected by an index or boolean array (the per-message arrays kept whole)."""
        return ImageBoxes(*(getattr(self, f)[rows] for f in self.ROWS), self.message_stamps, self.message_channels)
