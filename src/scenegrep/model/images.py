"""2-D image-space detections per camera channel (the perception streams of SpREs).

A frame holds zero or more *samples* (one per camera channel, each with its
image path and size in pixels); a sample holds zero or more *boxes*. Boxes are
centre-based: centre (cx, cy), width w and height h in pixels, ``rotation`` in
radians for oriented boxes (0 for axis-aligned ones, flagged by ``oriented``),
a detector ``score``, and optionally the row of the tracked object they belong
to (-1 when the stream has no identities, as in STREM JSON).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .table import RowTable


@dataclass(frozen=True, eq=False)
class SampleTable(RowTable):
    """One row per (frame, channel) sample; ``channel`` codes index ``channels``."""

    channels: tuple[str, ...]
    frame: np.ndarray
    channel: np.ndarray
    image_path: np.ndarray
    image_width: np.ndarray
    image_height: np.ndarray


@dataclass(frozen=True, eq=False)
class BoxTable(RowTable):
    """One row per detection box; ``category`` codes index ``classes``, ``sample`` is a sample row."""

    classes: tuple[str, ...]
    sample: np.ndarray
    category: np.ndarray
    score: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    w: np.ndarray
    h: np.ndarray
    rotation: np.ndarray
    oriented: np.ndarray
    object: np.ndarray


@dataclass(frozen=True, eq=False)
class ImageLayer:
    """The samples and boxes of a trace; samples sorted by frame, boxes by sample."""

    samples: SampleTable
    boxes: BoxTable

    def equals(self, other: object) -> bool:
        """Table-wise equality."""
        return isinstance(other, ImageLayer) and self.samples.equals(other.samples) and self.boxes.equals(other.boxes)

    def keep_samples(self, keep: np.ndarray, frame_map: np.ndarray, object_map: np.ndarray) -> ImageLayer:
        """Keep the samples selected by boolean mask ``keep`` and their boxes; renumber frames and
        objects through ``frame_map`` / ``object_map`` (old row -> new row, -1 when dropped; a box's
        object -1, no object, indexes the appended -1)."""
        new_sample = np.cumsum(keep) - 1
        samples = self.samples.take(keep)
        samples = SampleTable(
            samples.channels,
            frame_map[samples.frame].astype(np.int32),
            samples.channel,
            samples.image_path,
            samples.image_width,
            samples.image_height,
        )
        box_keep = keep[self.boxes.sample]
        boxes = self.boxes.take(box_keep)
        objects = np.append(object_map, -1)[boxes.object].astype(np.int32)
        boxes = BoxTable(
            boxes.classes,
            new_sample[boxes.sample].astype(np.int32),
            boxes.category,
            boxes.score,
            boxes.cx,
            boxes.cy,
            boxes.w,
            boxes.h,
            boxes.rotation,
            boxes.oriented,
            objects,
        )
        return ImageLayer(samples, boxes)


class ImageLayerBuilder:
    """Collects samples and boxes one at a time (as a reader meets them) into an :class:`ImageLayer`.

    Samples must be added in frame order and each box after its sample.
    """

    def __init__(self) -> None:
        self._channels: dict[str, int] = {}
        self._classes: dict[str, int] = {}
        self._samples: tuple[list, ...] = ([], [], [], [], [])
        self._boxes: tuple[list, ...] = ([], [], [], [], [], [], [], [], [], [])

    def add_sample(self, frame: int, channel: str, image_path: str, width: int, height: int) -> int:
        """Add a sample of a frame (position); returns its row."""
        code = self._channels.setdefault(channel, len(self._channels))
        for column, value in zip(self._samples, (frame, code, image_path, width, height)):
            column.append(value)
        return len(self._samples[0]) - 1

    def add_box(
        self,
        sample: int,
        category: str,
        score: float,
        cx: float,
        cy: float,
        w: float,
        h: float,
        rotation: float | None = None,
        object_row: int = -1,
    ) -> None:
        """Add a box (pixels; ``rotation`` in radians for an oriented box, None for an axis-aligned one)."""
        code = self._classes.setdefault(category, len(self._classes))
        values = (sample, code, score, cx, cy, w, h, rotation or 0.0, rotation is not None, object_row)
        for column, value in zip(self._boxes, values):
            column.append(value)

    def build(self) -> ImageLayer:
        """The layer of everything added."""
        frame, channel, path, width, height = self._samples
        samples = SampleTable(
            tuple(self._channels),
            np.asarray(frame, np.int32),
            np.asarray(channel, np.int32),
            np.array(path, dtype=object),
            np.asarray(width, np.int32),
            np.asarray(height, np.int32),
        )
        sample, category, score, *geometry, oriented, obj = self._boxes
        boxes = BoxTable(
            tuple(self._classes),
            np.asarray(sample, np.int32),
            np.asarray(category, np.int32),
            np.asarray(score, np.float32),
            *(np.asarray(g, np.float64) for g in geometry),
            np.asarray(oriented, bool),
            np.asarray(obj, np.int32),
        )
        return ImageLayer(samples, boxes)


def concatenate_layers(parts: list[tuple[ImageLayer | None, int, np.ndarray]]) -> ImageLayer | None:
    """The image layers of consecutive traces as one: each part is (layer or None, the frame
    position its trace starts at, its object rows -> rows of the whole); channels and classes
    are the union of the parts' in order of first appearance. None when no part has a layer."""
    layers = [(layer, offset, objects) for layer, offset, objects in parts if layer is not None]
    if not layers:
        return None
    channels: dict[str, int] = {}
    classes: dict[str, int] = {}
    samples: list[tuple] = []
    boxes: list[tuple] = []
    sample_offset = 0
    for layer, offset, objects in layers:
        s, b = layer.samples, layer.boxes
        channel_map = np.array([channels.setdefault(c, len(channels)) for c in s.channels] + [0], dtype=np.int32)
        class_map = np.array([classes.setdefault(c, len(classes)) for c in b.classes] + [0], dtype=np.int32)
        samples.append((s.frame + offset, channel_map[s.channel], s.image_path, s.image_width, s.image_height))
        box_objects = np.append(np.asarray(objects, dtype=np.int32), -1)[b.object]
        boxes.append(
            (
                b.sample + sample_offset,
                class_map[b.category],
                b.score,
                b.cx,
                b.cy,
                b.w,
                b.h,
                b.rotation,
                b.oriented,
                box_objects,
            )
        )
        sample_offset += len(s)
    frame, channel, path, width, height = (np.concatenate(c) for c in zip(*samples))
    sample, category, score, cx, cy, w, h, rotation, oriented, obj = (np.concatenate(c) for c in zip(*boxes))
    return ImageLayer(
        SampleTable(tuple(channels), frame.astype(np.int32), channel, path, width, height),
        BoxTable(
            tuple(classes),
            sample.astype(np.int32),
            category,
            score,
            cx,
            cy,
            w,
            h,
            rotation,
            oriented,
            obj.astype(np.int32),
        ),
    )
