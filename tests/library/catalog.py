"""The library of real-situation queries, ``examples/queries/real/``, as the tests and the
benchmark read it.

Every query file starts with two header lines::

    # Finds: <what it finds, one line>
    # Run: <kind> window=3s tolerance_heading=0.2 unknown_layers=permissive

``Run`` names the query kind (scenario, scene or spre) and its options as ``name=value`` pairs,
the options of :class:`scenegrep.dataset.queries.QuerySpec` (the command-line options with ``_``
for ``-``); further comment lines say why. A query means ``scenegrep <kind> FILE DATA...`` with
those options. The tests run it as ``--dataset`` does, over every input ingested once per
process and per unknown-layers choice (labelled under the query's own choice, as a query over
files labels them): the same rows as over files (tests/dataset checks the two modes equal), for
one reading and labelling of each recording instead of one per query.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from scenegrep.dataset.ingest import ingest
from scenegrep.dataset.queries import QuerySpec
from scenegrep.dataset.run import RunOptions, run_query
from tests.conftest import REPO, SHARED

LIBRARY = REPO / "examples" / "queries" / "real"
SUFFIXES = {"scenario": ".scenic", "scene": ".scenic", "spre": ".spre"}

SENSOR_RECORDINGS = (
    "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede",
    "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76",
    *(
        f"nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{scene}.pkl"
        for scene in ("0061", "0103", "0553", "0655", "0757", "0796", "0916", "1077", "1094", "1100")
    ),
)
"""The 12 real sensor recordings (AV2 sensor logs and nuScenes scenes), relative to real_data."""

OTHER_RECORDINGS = (
    "av2/forecasting/0a1e6f0a-1817-4a98-b02e-db8c9327d151",
    "waymo_womd/motion_data_one_scenario.tfrecord",
    "waymo_womd/womd_scenario_input.tfrecord",
    "waymo_womd/sd_waymo_v1.2_eb4b91b10ca94ff2.pkl",
    "commonroad_ngsim/USA_Lanker-1_1_T-1.xml",
    "commonroad_ngsim/USA_Peach-4_8_T-1.xml",
    "commonroad_ngsim/USA_US101-3_3_T-1.xml",
    "commonroad_ngsim/USA_US101-4_1_T-1.xml",
)
RECORDINGS = SENSOR_RECORDINGS + OTHER_RECORDINGS
"""Every recording of ../shared/real_data, relative to it."""


@dataclass(frozen=True)
class LibraryQuery:
    """One query file of the library: its ``name`` (file stem), ``finds`` (the header's
    sentence) and the ``spec`` it runs as."""

    name: str
    path: Path
    finds: str
    spec: QuerySpec

    def command(self, data: str) -> str:
        """The command line that runs this query over ``data``."""
        options = []
        for name, value in self.spec.options:
            default = value is None or value is False or (name == "skip" and value == 0)
            if not default:
                flag = "--" + name.replace("_", "-")
                options.append(flag if value is True else f"{flag} {value}")
        return " ".join(["scenegrep", self.spec.kind, str(self.path.relative_to(REPO)), data, *options])


def parse_value(text: str) -> Any:
    """An option value of a ``Run`` line: a bool, int or float when it reads as one, else text."""
    if text in ("true", "false"):
        return text == "true"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


def read_query(path: Path) -> LibraryQuery:
    """The library query in ``path`` (ValueError naming the file if its header is malformed)."""
    text = path.read_text(encoding="utf-8")
    lines = text.splitlines()
    if len(lines) < 2 or not lines[0].startswith("# Finds: ") or not lines[1].startswith("# Run: "):
        raise ValueError(f"{path}: the first two lines must be '# Finds: ...' and '# Run: ...'")
    kind, *pairs = lines[1].removeprefix("# Run: ").split()
    if path.suffix != SUFFIXES.get(kind):
        raise ValueError(f"{path}: a {kind} query must be a {SUFFIXES.get(kind)} file")
    options = dict(pair.split("=", 1) for pair in pairs)
    body = text if kind != "spre" else "\n".join(line for line in lines if not line.startswith("#"))
    spec = QuerySpec.of(kind, body, str(path), **{k: parse_value(v) for k, v in options.items()})
    return LibraryQuery(path.stem, path, lines[0].removeprefix("# Finds: ").strip(), spec)


def library() -> list[LibraryQuery]:
    """Every query of the library, by name."""
    paths = sorted(p for p in LIBRARY.iterdir() if p.suffix in (".scenic", ".spre"))
    return [read_query(path) for path in paths]


@cache
def query(name: str) -> LibraryQuery:
    """The library query called ``name``."""
    for found in library():
        if found.name == name:
            return found
    raise KeyError(name)


INPUTS = (*RECORDINGS, "examples/sample")
"""Every input the library runs on: the real recordings and the simulated sample."""


def input_path(recording: str) -> Path:
    """The path of an input of :data:`INPUTS` (real_data-relative, or repository-relative)."""
    return (REPO if recording.startswith("examples/") else SHARED / "real_data") / recording


_FOLDER = tempfile.TemporaryDirectory(prefix="scenegrep-library-")


@cache
def dataset(unknown_layers: str) -> Path:
    """Every input ingested, labelled under the choice ``unknown_layers``, once per process."""
    root = Path(_FOLDER.name) / unknown_layers
    report = ingest([str(input_path(r)) for r in INPUTS], root, jobs=1, unknown_layers=unknown_layers)
    assert not report.failed, report.failed
    return root


@cache
def _rows_by_input(name: str) -> dict[str, tuple[dict[str, Any], ...]]:
    """The results-table rows of query ``name`` over every input, by input."""
    spec = query(name).spec
    choice = spec.option("unknown_layers")
    assert choice is not None, f"{name}: the library's queries say how to treat unknown map layers"
    table = run_query(dataset(choice), spec, RunOptions(jobs=1)).table.to_pylist()
    found: dict[str, tuple[dict[str, Any], ...]] = {}
    for recording in INPUTS:
        path = str(input_path(recording).resolve())
        found[recording] = tuple(r for r in table if r["source"] == path or r["source"].startswith(path + "/"))
    return found


def rows(name: str, recording: str) -> tuple[dict[str, Any], ...]:
    """The results-table rows of query ``name`` over one input of :data:`INPUTS` (computed for
    every input at once, once per process)."""
    return _rows_by_input(name)[recording]


def matches(name: str, recording: str) -> list[dict[str, Any]]:
    """The match rows of query ``name`` over one recording; fails the test on a failed row."""
    found = rows(name, recording)
    failed = [row["error"] for row in found if row["status"] == "failed"]
    assert not failed, failed
    return [row for row in found if row["status"] == "match"]
