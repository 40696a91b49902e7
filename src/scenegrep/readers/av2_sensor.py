"""Argoverse 2 sensor-dataset logs: 3-D cuboid annotations in the ego frame, ego poses
in the city frame, and the log's vector map.

A log directory holds ``annotations.feather`` (timestamp_ns, track_uuid, category,
length/width/height_m, box rotation qw..qz and centre tx..tz_m in the *ego* frame),
``city_SE3_egovehicle.feather`` (the ego pose per timestamp_ns) and
``map/log_map_archive_*.json``. Boxes are moved to the city frame with the ego pose
of their timestamp: ``city = R_ego · box + t_ego``. Every annotation timestamp is a
frame; frame times are seconds since the first. The ego vehicle becomes object
``ego`` (class REGULAR_VEHICLE, size :data:`EGO_SIZE_M`). Velocities come from
finite differences of positions (the log has none); the trace attribute
:data:`~scenegrep.model.kinematics.ESTIMATED_VELOCITY` says so (queries read them, documented).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.feather as feather

from ..errors import UserError, at
from ..model import LabelTrace, MapSource, ObjectTable, StateTable, TraceSource
from ..model.geometry import heading_from_yaw, rotation_matrices
from ..model.kinematics import ESTIMATED_VELOCITY, with_derived_velocity
from .av2_map import FORMAT as MAP_FORMAT
from .av2_map import find_map
from .common import reading
from ..wording import plural

FORMAT = "av2-sensor"
ANNOTATIONS = "annotations.feather"
POSES = "city_SE3_egovehicle.feather"
EGO_ID = "ego"
EGO_SIZE_M = (4.87, 1.85, 1.48)
"""Length, width, height (m) of the AV2 vehicle (a Ford Fusion Hybrid); the logs do not state it."""

_ANNOTATION_COLUMNS = (
    "timestamp_ns",
    "track_uuid",
    "category",
    "length_m",
    "width_m",
    "height_m",
    "qw",
    "qx",
    "qy",
    "qz",
    "tx_m",
    "ty_m",
    "tz_m",
)
_POSE_COLUMNS = ("timestamp_ns", "qw", "qx", "qy", "qz", "tx_m", "ty_m", "tz_m")


def is_log(directory: Path) -> bool:
    """Whether a directory is an AV2 sensor log."""
    return (directory / ANNOTATIONS).is_file() and (directory / POSES).is_file()


def _columns(path: Path, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    with reading(path, "Argoverse 2 feather file", pa.ArrowException):
        table = feather.read_table(path)
        table.validate(full=True)  # Feather buffers are used as they lie: a bad offset crashes Arrow later
    missing = [n for n in names if n not in table.column_names]
    if missing:
        raise UserError(f"missing {plural('column', len(missing))} {', '.join(missing)}", at(path))
    if table.num_rows == 0:
        raise UserError("holds no rows", at(path))
    return {n: table.column(n).to_numpy(zero_copy_only=False) for n in names}


def read_trace(directory: str | Path) -> LabelTrace:
    """Read an AV2 sensor log directory into a trace in the city frame."""
    directory = Path(directory)
    ann = _columns(directory / ANNOTATIONS, _ANNOTATION_COLUMNS)
    pose = _columns(directory / POSES, _POSE_COLUMNS)
    stamps, frame = np.unique(ann["timestamp_ns"], return_inverse=True)
    pose_row = np.searchsorted(pose["timestamp_ns"], stamps)
    pose_row = np.minimum(pose_row, len(pose["timestamp_ns"]) - 1)
    if not np.array_equal(pose["timestamp_ns"][pose_row], stamps):
        raise UserError("some annotation timestamps have no ego pose", at(directory / POSES))
    r_ego = rotation_matrices(*(pose[q][pose_row] for q in ("qw", "qx", "qy", "qz")))
    t_ego = np.stack([pose[c][pose_row] for c in ("tx_m", "ty_m", "tz_m")], axis=1)
    box = np.stack([ann[c] for c in ("tx_m", "ty_m", "tz_m")], axis=1)
    city = np.einsum("nij,nj->ni", r_ego[frame], box) + t_ego[frame]
    r_box = np.einsum("nij,njk->nik", r_ego[frame], rotation_matrices(*(ann[q] for q in ("qw", "qx", "qy", "qz"))))
    yaw = np.arctan2(r_box[:, 1, 0], r_box[:, 0, 0])
    ego_yaw = np.arctan2(r_ego[:, 1, 0], r_ego[:, 0, 0])
    tracks, track_row = np.unique(ann["track_uuid"].astype(str), return_inverse=True)
    first_category = ann["category"][np.unique(track_row, return_index=True)[1]]
    n, f = len(tracks), len(stamps)
    objects = ObjectTable.build([*tracks.tolist(), EGO_ID], [*first_category.astype(str).tolist(), "REGULAR_VEHICLE"])
    states = StateTable.build(
        frame=np.r_[frame, np.arange(f)],
        object=np.r_[track_row, np.full(f, n)],
        x=np.r_[city[:, 0], t_ego[:, 0]],
        y=np.r_[city[:, 1], t_ego[:, 1]],
        z=np.r_[city[:, 2], t_ego[:, 2]],
        heading=heading_from_yaw(np.r_[yaw, ego_yaw]),
        length=np.r_[ann["length_m"], np.full(f, EGO_SIZE_M[0])],
        width=np.r_[ann["width_m"], np.full(f, EGO_SIZE_M[1])],
        height=np.r_[ann["height_m"], np.full(f, EGO_SIZE_M[2])],
    )
    times = (stamps - stamps[0]) / 1e9
    order = states.sort_order()
    states = with_derived_velocity(states if order is None else states.take(order), times)
    map_path = find_map(directory)
    return LabelTrace.build(
        directory.name,
        np.arange(f),
        times,
        objects,
        states,
        ego=EGO_ID,
        attributes={
            "dataset": "argoverse2-sensor",
            "log_id": directory.name,
            "time_origin_ns": int(stamps[0]),
            ESTIMATED_VELOCITY: "positions",
        },
        source=TraceSource(str(directory), FORMAT),
        map_source=None if map_path is None else MapSource(str(map_path), MAP_FORMAT),
    )
