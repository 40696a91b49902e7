"""The C pass of framing's box math (readers/ros/_place.c) against the numpy formulas it replaces
(transforms.product, rotated and yaw's terms), bit for bit, on strided inputs and outputs, and
its refusals of arrays it cannot use."""

from __future__ import annotations

import numpy as np
import pytest

from scenegrep.readers.ros._place import place
from scenegrep.readers.ros.transforms import _sum, normalised, product, rotated

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
    """The (10, n) values by the numpy formulas, box by box's transform (identity where -1): x,
    y, z, yaw's sine term, length, width, height, vx, vy, yaw's cosine term."""
    moved = b["each"] >= 0
    t, s = b["turn"][b["each"]].T, b["shift"][b["each"]].T
    position = np.where(moved, np.array(rotated(t, b["xyz"].T)) + s, b["xyz"].T)
    rotation = np.where(moved, np.array(product(t, b["quat"].T)), b["quat"].T)
    x, y, z, w = rotation
    sine, cosine = _sum((w, z, 1), (x, y, 1)) * 2.0, 1.0 - _sum((y, y, 1), (z, z, 1)) * 2.0
    velocity = rotated(rotation, b["velocity"].T)[:2]
    return np.vstack([position, sine, b["size"].T, velocity, cosine])


ARGUMENTS = ("xyz", "quat", "size", "velocity", "each", "shift", "turn", "dest", "out", "cosine")


def test_place_is_the_numpy_formulas_on_strided_arrays(boxes):
    rng = np.random.default_rng(5)
    dest = rng.permutation(2 * N)[:N]  # (rows of a longer output, in any order)
    dest[::7] = -1  # (not written)
    grid = np.full((10, 3 * 2 * N), -7.0)
    out = list(grid[:, ::3])  # (strided outputs: every third row of a (10, .) array)
    place(*(boxes[k] for k in ARGUMENTS[:7]), dest, out[:9], out[9])
    written = dest >= 0
    got, expected = grid[:, ::3][:, dest[written]], _reference(boxes)[:, written]
    np.testing.assert_array_equal(got, expected)  # (bit for bit; NaN where the velocity is)
    untouched = np.ones(3 * 2 * N, dtype=bool)
    untouched[3 * dest[written]] = False
    assert (grid[:, untouched] == -7.0).all()  # (nothing written elsewhere)
    still = written & (boxes["each"] == -1)
    np.testing.assert_array_equal(grid[:3, ::3][:, dest[still]], boxes["xyz"][still].T)  # (the map frame's as is)


def test_place_of_no_boxes_writes_nothing():
    empty3, empty4, none = np.empty((0, 3)), np.empty((0, 4)), np.empty(0, dtype=np.int64)
    out = [np.zeros(3) for _ in range(10)]
    place(empty3, empty4, empty3, empty3, none, empty3, empty4, none, out[:9], out[9])
    assert not np.any(out)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"each": np.full(N, M)}, "not a transform row"),
        ({"each": np.full(N, -2)}, "not a transform row"),
        ({"dest": np.full(N, N)}, "not a row of out"),
        ({"dest": np.full(N, -2)}, "not a row of out"),
        ({"each": np.zeros(N, dtype=np.int32)}, "int64"),
        ({"xyz": np.zeros((N, 2))}, "xyz"),
        ({"quat": np.zeros((N, 4), dtype=np.float32)}, "quat"),
        ({"size": np.zeros((N - 1, 3))}, "different lengths"),
        ({"turn": np.zeros((M + 1, 4))}, "different lengths"),
        ({"out": [np.zeros(N)] * 8}, "9 arrays"),
        ({"out": [np.zeros(N)] * 8 + [np.zeros(N - 1)]}, "different lengths"),
        ({"out": [np.zeros(N)] * 8 + [np.zeros((N, 1))]}, "out vy"),
        ({"cosine": np.zeros(N + 1)}, "different lengths"),
        ({"cosine": np.zeros(N, dtype=np.float32)}, "cosine"),
    ],
)
def test_place_refuses_what_it_cannot_use(boxes, change, message):
    arguments = {**boxes, "dest": np.arange(N), "out": [np.zeros(N) for _ in range(9)], "cosine": np.zeros(N), **change}
    with pytest.raises(ValueError, match=message):
        place(*(arguments[k] for k in ARGUMENTS))


def test_place_refuses_a_read_only_output(boxes):
    out = [np.zeros(N) for _ in range(9)]
    out[4].flags.writeable = False
    with pytest.raises((ValueError, BufferError)):
        place(*(boxes[k] for k in ARGUMENTS[:7]), np.arange(N), out, np.zeros(N))
