"""Argoverse 2 motion-forecasting scenarios: ``scenario_<id>.parquet`` tracks at 10 Hz in
the city frame, with the scenario's ``log_map_archive_<id>.json`` beside it.

Columns used: track_id, object_type, timestep, position_x/y, heading (yaw from +x,
radians), velocity_x/y, start/end_timestamp (ns), num_timestamps, city,
focal_track_id. The autonomous vehicle is track ``AV``, the trace's ego. The
scenarios give no object sizes: length, width and height are NaN.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from ..errors import UserError, at
from ..model import LabelTrace, MapSource, ObjectTable, StateTable, TraceSource
from ..model.geometry import heading_from_yaw
from ..model.trace import checked_frame_count
from .av2_map import FORMAT as MAP_FORMAT
from .av2_map import find_map
from .common import reading
from ..wording import plural

FORMAT = "av2-forecasting"
EGO_ID = "AV"
_COLUMNS = (
    "track_id",
    "object_type",
    "timestep",
    "position_x",
    "position_y",
    "heading",
    "velocity_x",
    "velocity_y",
    "start_timestamp",
    "end_timestamp",
    "num_timestamps",
)


def scenario_file(path: Path) -> Path | None:
    """The scenario parquet of a scenario directory (or the file itself)."""
    if path.is_file():
        return path if path.name.startswith("scenario_") and path.suffix == ".parquet" else None
    found = sorted(path.glob("scenario_*.parquet"))
    return found[0] if found else None


def read_trace(path: str | Path) -> LabelTrace:
    """Read an AV2 forecasting scenario (its parquet file or its directory)."""
    path = Path(path)
    file = scenario_file(path)
    if file is None:
        raise UserError("no scenario_*.parquet here", at(path))
    with reading(file, "Argoverse 2 scenario parquet", pa.ArrowException):
        table = pq.read_table(file)
    missing = [c for c in _COLUMNS if c not in table.column_names]
    if missing:
        raise UserError(f"missing {plural('column', len(missing))} {', '.join(missing)}", at(file))
    col = {c: table.column(c).to_numpy(zero_copy_only=False) for c in table.column_names}
    tracks, track_row = np.unique(col["track_id"].astype(str), return_inverse=True)
    if table.num_rows == 0:
        raise UserError("holds no rows", at(file))
    n_steps = checked_frame_count(int(col["num_timestamps"][0]))
    interval = (float(col["end_timestamp"][0]) - float(col["start_timestamp"][0])) / 1e9 / max(n_steps - 1, 1)
    first = np.unique(track_row, return_index=True)[1]
    objects = ObjectTable.build(tracks.tolist(), col["object_type"][first].astype(str).tolist())
    states = StateTable.build(
        frame=col["timestep"],
        object=track_row,
        x=col["position_x"],
        y=col["position_y"],
        heading=heading_from_yaw(col["heading"]),
        vx=col["velocity_x"],
        vy=col["velocity_y"],
    )
    attributes = {
        "dataset": "argoverse2-forecasting",
        "scenario_id": file.stem.removeprefix("scenario_"),
        "time_origin_ns": int(col["start_timestamp"][0]),
    }
    for name in ("city", "focal_track_id"):
        if name in col:
            attributes[name] = str(col[name][0])
    map_path = find_map(file.parent)
    return LabelTrace.build(
        attributes["scenario_id"],
        np.arange(n_steps),
        np.arange(n_steps) * interval,
        objects,
        states,
        ego=EGO_ID if EGO_ID in set(tracks.tolist()) else None,
        attributes=attributes,
        source=TraceSource(str(path), FORMAT),
        map_source=None if map_path is None else MapSource(str(map_path), MAP_FORMAT),
    )
