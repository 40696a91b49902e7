"""Every row of docs/scenic-constructs.toml proves its construct's status, and the docs table is its rendering.

Run ``python -m tests.test_constructs`` to rewrite docs/scenic-constructs.md after editing the data.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import math
import sys
import tomllib
from functools import cache
from pathlib import Path

import numpy as np
import pytest
import shapely

from scenegrep.errors import UserError
from scenegrep.model import Area
from scenegrep.scenario import ScenarioOptions, compile_scenario
from scenegrep.scene import SceneOptions, compile_scene
from scenegrep.scene.domain import UNMODELLED_PROPERTIES
from tests.scenario.worked_example import worked_map, worked_trace
from tests.scene.frames import HEADER, MAP, trace_of

ROOT = Path(__file__).parents[1]
DATA = ROOT / "docs" / "scenic-constructs.toml"
DOC = ROOT / "docs" / "scenic-constructs.md"
FILENAME = "constructs.scenic"
STATUSES = {"modelled", "rejected", "extension", "no effect", "not observed"}
CATEGORIES = ("specifier", "property", "operator", "statement", "name")
TITLES = {
    "specifier": "Specifiers",
    "property": "Properties",
    "operator": "Operators",
    "statement": "Statements",
    "name": "Names, classes and functions",
}
WALKABLE_MAP = dataclasses.replace(
    MAP,
    sidewalks=(Area("w", shapely.box(-6, 0, -3.5, 100), centreline=np.array([[-4.75, 0], [-4.75, 100]])),),
    shoulders=(Area("h", shapely.box(7, 0, 9.5, 100)),),
    unknown_layers=frozenset(),
)
"""The synthetic map with sidewalks (oriented north) and shoulders, publishing every layer."""


@cache
def data() -> dict:
    return tomllib.loads(DATA.read_text(encoding="utf-8"))


def rows() -> list[dict]:
    return data()["row"]


def frames(name: str) -> list[dict]:
    """A frame set of the data, headings converted from degrees to radians."""
    return [
        {oid: (spec[0], spec[1], spec[2], math.radians(spec[3]), *spec[4:]) for oid, spec in frame.items()}
        for frame in data()["frames"][name]
    ]


def match(program: str, frame_set: str) -> list[bool]:
    query = compile_scene(HEADER + program, FILENAME)
    result = query.match(trace_of(*frames(frame_set)), WALKABLE_MAP, SceneOptions())
    return result.matched.tolist()


# ---------------------------------------------------------------------------- the rows
@pytest.mark.parametrize("row", rows(), ids=lambda row: f"{row['category']}: {row['construct']}")
def test_row(row):
    assert row["category"] in CATEGORIES and {row["scene"], row["scenario"]} <= STATUSES
    if "test" in row:
        _check_reference(row)
    elif "expect" in row:
        _check_answers(row)
    elif "frames" in row:
        _check_unknown(row)
    else:
        _check_rejection(row)


def _check_answers(row: dict) -> None:
    """A modelled row: the program's answer per frame, worked out by hand, depends on the frame."""
    assert row["scene"] in ("modelled", "extension", "no effect")
    expect = row["expect"]
    assert True in expect and False in expect, "a row's frames must show the construct deciding something"
    assert match(row["program"], row["frames"]) == expect
    compile_scenario(HEADER + row["program"], FILENAME)  # modelled in scenario queries too: the same scene


def _check_unknown(row: dict) -> None:
    """A modelled feature no data has: matching is a one-line error naming it, never an answer."""
    with pytest.raises(UserError) as caught:
        match(row["program"], row["frames"])
    assert caught.value.one_line().startswith(row["error"])


def _check_rejection(row: dict) -> None:
    """A rejected row: compiling is a one-line error at the construct's line:column, in both query kinds."""
    assert row["scene"] == row["scenario"] == "rejected"
    for compile_query in (compile_scene, compile_scenario):
        with pytest.raises(UserError) as caught:
            compile_query(HEADER + row["program"], FILENAME)
        line = caught.value.one_line()
        assert line.startswith(f"{FILENAME}:{row['error']}"), line
        assert "\n" not in line


def _check_reference(row: dict) -> None:
    """A row proved by another test: that test exists and its source uses the construct."""
    path, name = row["test"].split("::")
    module = importlib.import_module(path.removesuffix(".py").replace("/", "."))
    function = getattr(module, name)
    assert row["needle"] in inspect.getsource(function)


def test_local_path_names_a_file_beside_the_program(tmp_path):
    """``param map = localPath(...)``: the map beside the program is the one read for a trace without one."""
    program = str(tmp_path / "q" / "query.scenic")
    query = compile_scene(HEADER + "param map = localPath('town.xodr')\nego = new Car on road\n", program)
    assert query.program.map_path == str(tmp_path / "q" / "town.xodr")
    with pytest.raises(UserError, match="town.xodr"):  # read when a trace needs it: here, missing
        query.match(trace_of(*frames("dynamics")))


def test_library_behaviour_arguments_are_not_observed():
    """Labels name a primitive behaviour (FollowLane), not its intentions: Fig. 1 with other target
    speeds and lane arguments finds the same windows on the worked example."""
    text = (ROOT / "examples/queries/fig1_lane_change.scenic").read_text(encoding="utf-8")
    changed = text.replace("target_speed=10", "target_speed=99").replace("self.laneSection._laneToLeft", "None")
    assert changed.count("target_speed=99") == 3
    answers = []
    for program in (text, changed):
        result = compile_scenario(program, FILENAME).match(
            worked_trace(), 5, worked_map(), ScenarioOptions(find_all=True)
        )
        answers.append([(m.correspondence, m.starts.tolist()) for m in result.matches])
    assert answers[0] == answers[1] and answers[0]


def test_every_unmodelled_property_has_its_row():
    properties = {row["construct"].split(" ")[0] for row in rows() if row["category"] == "property"}
    assert set(UNMODELLED_PROPERTIES) <= properties


def test_the_doc_is_the_rendering_of_the_data():
    assert DOC.read_text(encoding="utf-8") == render(), "run: python -m tests.test_constructs"


# ---------------------------------------------------------------------------- the doc
INTRO = """# Scenic constructs in scenegrep's queries

Every specifier, property, operator, statement and name of Scenic 3.1.1's language reference,
and its status in scene queries and in scenario queries (a scenario's initial scene is a scene
query, so every construct of a scene has the same status there):

- **modelled**: the query means what Scenic means (in 2-D compatibility mode);
- **rejected**: an error naming the file and line:column, exit code 2 — never silently dropped;
- **extension**: modelled, although Scenic 3.1.1 does not define it;
- **no effect**: accepted, and Scenic gives it no effect there either (a scene is the initial
  state, so behaviours do not shape it; colours only change drawings);
- **not observed**: accepted, but labels cannot show it: the intentions of the driving
  library's behaviours (`FollowLaneBehavior(target_speed=10)` is any FollowLane labelling,
  whatever its target speed; seed 000's primitives are labels). The query admits every value.

Names Scenic 3.1.1 does not define are errors, as in Scenic (a `NameError`), unless listed
as extensions. Dynamic properties (`speed`, `velocity`, `angularSpeed`) are matched against the
velocities of the labels within `--tolerance-speed` (m/s); where a trace has no velocity for an
object a query needs, the answer is unknown, and the query stops with a one-line error naming
the feature, the trace, the object and the frame (never "true"). No data format scenegrep
reads has angular speeds, so `angularSpeed` is always unknown. AV2 sensor logs record no
velocities either: their reader estimates them from positions (for SpRE and the viewer), and
queries treat those estimates as unknown, not as labels. The other readers give the velocities
the data records (AV2 forecasting, Waymo, ScenarioNet, CommonRoad, scenegrep's JSON and Parquet
traces), or none.
Two kinematic extensions read the same velocities: `acceleration` (the finite differences of
the labeled velocities along each track; no data format records accelerations) and
`RelativeSpeed(X, Y)` (Scenic 3.1.1 has no `relative speed` operator).

Each row is tested by `tests/test_constructs.py`: modelled rows run a query that depends on
the construct on hand-built frames and check the answer worked out by hand; rejected rows
check the one-line error and its line:column. The data, with the test programs and frames, is
[`scenic-constructs.toml`](scenic-constructs.toml); this page is generated from it
(`python -m tests.test_constructs`).
"""


def render() -> str:
    """The Markdown page: the introduction, then one table per category."""
    parts = [INTRO]
    for category in CATEGORIES:
        chosen = [row for row in rows() if row["category"] == category]
        scene, scenario = _counts(chosen, "scene"), _counts(chosen, "scenario")
        parts.append(f"## {TITLES[category]} ({len(chosen)} rows; scene: {scene}; scenario: {scenario})\n")
        parts.append("| Construct | Scene query | Scenario query | Note |\n|---|---|---|---|")
        parts.extend(
            f"| `{row['construct']}` | {row['scene']} | {row['scenario']} | {_cell(row.get('note', ''))} |"
            for row in chosen
        )
        parts.append("")
    return "\n".join(parts)


def _counts(chosen: list[dict], kind: str) -> str:
    statuses = [row[kind] for row in chosen]
    return ", ".join(f"{statuses.count(s)} {s}" for s in sorted(STATUSES) if s in statuses)


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


if __name__ == "__main__":
    DOC.write_text(render(), encoding="utf-8")
    print(f"wrote {DOC.relative_to(ROOT)}", file=sys.stderr)
