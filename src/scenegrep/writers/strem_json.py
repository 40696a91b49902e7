"""Frames of a trace as a STREM JSON v0.2.0 document (``scenegrep spre --export``)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..model import LabelTrace

STREM_VERSION = "0.2.0"
"""The STREM JSON version written (and the one :mod:`scenegrep.readers.strem_json` reads)."""


def _box(trace: LabelTrace, k: int) -> dict[str, Any]:
    boxes = trace.images.boxes  # type: ignore[union-attr]
    region: dict[str, Any] = {
        "center": {"x": float(boxes.cx[k]), "y": float(boxes.cy[k])},
        "dimensions": {"w": float(boxes.w[k]), "h": float(boxes.h[k])},
    }
    kind = "aabb"
    if boxes.oriented[k]:
        region["rotation"] = float(boxes.rotation[k])
        kind = "obb"
    return {
        "class": boxes.classes[boxes.category[k]],
        "score": float(boxes.score[k]),
        "bbox": {"type": f"@stremf/bbox/{kind}", "region": region},
    }


def strem_document(trace: LabelTrace, start: int, end: int, channels: tuple[str, ...] | None = None) -> dict[str, Any]:
    """The frames at positions [start, end) with their kept channels' samples and boxes."""
    frames = []
    images = trace.images
    for f in range(start, end):
        samples = []
        if images is not None:
            for row in np.flatnonzero(images.samples.frame == f).tolist():
                channel = images.samples.channels[images.samples.channel[row]]
                if channels is not None and channel not in channels:
                    continue
                boxes = np.flatnonzero(images.boxes.sample == row).tolist()
                samples.append(
                    {
                        "type": "@stremf/sample/detection",
                        "channel": channel,
                        "image": {
                            "path": str(images.samples.image_path[row]),
                            "dimensions": {
                                "width": int(images.samples.image_width[row]),
                                "height": int(images.samples.image_height[row]),
                            },
                        },
                        "annotations": [_box(trace, k) for k in boxes],
                    }
                )
        frames.append({"index": int(trace.frame_index[f]), "samples": samples})
    return {"version": STREM_VERSION, "frames": frames}
