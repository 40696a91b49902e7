"""The C pass of framing's box math (readers/ros/_place.c) against the numpy formulas it replaces
(transforms.product, rotated, yaw and geometry.heading_from_yaw), on strided inputs and output,
and its refusals of arrays it cannot use."""

from __future__ import annotations

import numpy as np
import pytest

from scenegrep.model.geometry import heading_from_yaw
from scenegrep.readers.ros._place import place
from scenegrep.readers.ros.transforms import normalised, product, rotated, yaw

N, M = 500, 7


def _unit(rng: np.random.Generator, n: int) -> np.ndarray:
    return normalised(rng.normal(size=(n, 4)))


@pytest.fixture(scope="module")
def boxes() -> dict[str, np.ndarray]:
    """Boxes as strided views (columns of one record array, as a decoder may give them), a
    transform table and each box's row in it (-1: in the map frame)."""
    rng = np.random.default_rng(18)
    record = rng.normal(scale=50.0, size=(N, 16))
    record[:, 3:7] = _unit(rng, N)
    record[::9, 13:16] = np.nan  # (no velocity given)
    each = rng.integers(-1, M, size=N)
    return {
        "xyz": record[:, 0:3],
        "quat": record[:, 3:7],
        "size": np.abs(record[:, 7:10]),
        "velocity": record[:, 13:16],
        "each": each,
        "shift": rng.normal(scale=1e3, size=(M, 3)),
        "turn": _unit(rng, M),
    }


def _reference(b: dict[str, np.ndarray]) -> np.ndarray:
    """The (9, n) values by the numpy formulas, box by box's transform (identity where -1)."""
    moved = b["each"] >= 0
    t, s = b["turn"][b["each"]].T, b["shift"][b["each"]].T
    position = np.where(moved, np.array(rotated(t, b["xyz"].T)) + s, b["xyz"].T)
    rotation = np.where(moved, np.array(product(t, b["quat"].T)), b["quat"].T)
    velocity = rotated(rotation, b["velocity"].T, axes=2)
    return np.vstack([position, heading_from_yaw(yaw(rotation)), b["size"].T, velocity])


def test_place_is_the_numpy_formulas_on_strided_arrays(boxes):
    grid = np.full((9, 3 * N), -7.0)
    out = grid[:, ::3]  # (a strided output: every third column)
    place(
        boxes["xyz"], boxes["quat"], boxes["size"], boxes["velocity"], boxes["each"], boxes["shift"], boxes["turn"], out
    )
    expected = _reference(boxes)
    np.testing.assert_array_equal(np.isnan(out), np.isnan(expected))
    assert np.nanmax(np.abs(out - expected)) < 1e-9  # (positions up to ~1e3 m: the last bits may differ in atan2)
    assert (grid[:, 1::3] == -7.0).all() and (grid[:, 2::3] == -7.0).all()  # nothing written beside
    still = boxes["each"] == -1
    np.testing.assert_array_equal(out[:3, still], boxes["xyz"][still].T)  # (the map frame's boxes as they are)


def test_place_of_no_boxes_writes_nothing():
    empty3, empty4 = np.empty((0, 3)), np.empty((0, 4))
    place(empty3, empty4, empty3, empty3, np.empty(0, dtype=np.int64), empty3, empty4, np.empty((9, 0)))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"each": np.full(N, M)}, "not a transform row"),
        ({"each": np.full(N, -2)}, "not a transform row"),
        ({"each": np.zeros(N, dtype=np.int32)}, "int64"),
        ({"xyz": np.zeros((N, 2))}, "xyz"),
        ({"quat": np.zeros((N, 4), dtype=np.float32)}, "quat"),
        ({"size": np.zeros((N - 1, 3))}, "different lengths"),
        ({"turn": np.zeros((M + 1, 4))}, "different lengths"),
        ({"out": np.zeros((8, N))}, "different lengths"),
    ],
)
def test_place_refuses_what_it_cannot_use(boxes, change, message):
    arguments = {**boxes, "out": np.zeros((9, N)), **change}
    names = ("xyz", "quat", "size", "velocity", "each", "shift", "turn", "out")
    with pytest.raises(ValueError, match=message):
        place(*(arguments[k] for k in names))


def test_place_refuses_a_read_only_output(boxes):
    out = np.zeros((9, N))
    out.flags.writeable = False
    with pytest.raises((ValueError, BufferError)):
        place(*(boxes[k] for k in ("xyz", "quat", "size", "velocity", "each", "shift", "turn")), out)
