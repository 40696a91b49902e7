"""The Scenic front end (parser -> adapter -> IR) and resolution errors: one line, file:line:column."""

from __future__ import annotations

import subprocess
import sys

import pytest

from scenegrep.errors import UserError
from scenegrep.scene import compile_scene
from scenegrep.scene.dependencies import analyse
from scenegrep.scenic import ir
from scenegrep.scenic.adapter import parse_program

HEADER = "model scenic.domains.driving.model\n"


def first(text: str) -> ir.Node:
    return parse_program(text, "t.scenic").statements[0]


def test_statements_become_ir_nodes():
    program = parse_program(
        "param weather = 'rain', n = 2\nmodel scenic.domains.driving.model\nego = new Car\n"
        "new Car ahead of ego\nrequire[0.7] ego.position.x > 0\nfor i in range(2):\n    pass\n",
        "t.scenic",
    )
    kinds = [type(s).__name__ for s in program.statements]
    assert kinds == ["Param", "Param", "Model", "Assign", "Evaluate", "Require", "Repeat"]
    assert program.statements[3] == ir.Assign("ego", ir.New("Car", ()))
    assert program.statements[5].probability == pytest.approx(0.7)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("x = 3 deg", ir.Operator("deg", (ir.Constant(3),))),
        ("x = 1 @ 2", ir.Operator("vector", (ir.Constant(1), ir.Constant(2)))),
        ("x = a relative to b", ir.Operator("relative to", (ir.Name("a"), ir.Name("b")))),
        ("x = a offset by b", ir.Operator("relative to", (ir.Name("a"), ir.Name("b")))),
        ("x = a offset along h by v", ir.Operator("offset along", (ir.Name("a"), ir.Name("h"), ir.Name("v")))),
        ("x = distance from a to b", ir.Operator("distance", (ir.Name("a"), ir.Name("b")))),
        ("x = distance to b", ir.Operator("distance", (ir.Name("b"), None))),
        ("x = angle from a to b", ir.Operator("angle", (ir.Name("a"), ir.Name("b")))),
        ("x = angle to b", ir.Operator("angle", (None, ir.Name("b")))),
        ("x = relative heading of a from b", ir.Operator("relative heading", (ir.Name("a"), ir.Name("b")))),
        ("x = apparent heading of a", ir.Operator("apparent heading", (ir.Name("a"), None))),
        ("x = relative position of a", ir.Operator("relative position", (ir.Name("a"), None))),
        ("x = follow f from p for 3", ir.Operator("follow", (ir.Name("f"), ir.Name("p"), ir.Constant(3)))),
        ("x = visible r", ir.Operator("visible", (ir.Name("r"),))),
        ("x = r visible from p", ir.Operator("visible from", (ir.Name("r"), ir.Name("p")))),
        ("x = a can see b", ir.Operator("can see", (ir.Name("a"), ir.Name("b")))),
        ("x = front left of o", ir.Operator("front left of", (ir.Name("o"),))),
        ("x = f at p", ir.Operator("field at", (ir.Name("f"), ir.Name("p")))),
        (
            "x = 1 < y < 3",
            ir.BoolOp(
                "and", (ir.Compare("<", ir.Constant(1), ir.Name("y")), ir.Compare("<", ir.Name("y"), ir.Constant(3)))
            ),
        ),
        ("x = a if c else b", ir.Conditional(ir.Name("c"), ir.Name("a"), ir.Name("b"))),
        ("x = Range(1, 2)", ir.Call("Range", (ir.Constant(1), ir.Constant(2)))),
    ],
)
def test_operators_become_ir_nodes(text, expected):
    statement = first(text)
    assert isinstance(statement, ir.Assign)
    assert statement.value == expected


@pytest.mark.parametrize(
    ("specifier", "name", "operands"),
    [
        ("at (1, 2)", "at", 1),
        ("on road", "on", 1),
        ("in road", "in", 1),
        ("contained in road", "contained in", 1),
        ("offset by (1, 2)", "offset by", 1),
        ("offset along 10 deg by (1, 2)", "offset along", 2),
        ("left of ego by 2", "left of", 2),
        ("right of ego", "right of", 2),
        ("ahead of ego by 2", "ahead of", 2),
        ("behind ego", "behind", 2),
        ("beyond ego by 3 from p", "beyond", 3),
        ("visible", "visible", 1),
        ("visible from p", "visible", 1),
        ("not visible", "not visible", 1),
        ("following roadDirection from p for 5", "following", 3),
        ("facing 3", "facing", 1),
        ("facing toward p", "facing toward", 1),
        ("facing directly toward p", "facing toward", 1),
        ("facing away from p", "facing away from", 1),
        ("apparently facing 3 from p", "apparently facing", 2),
        ("with width 3", "with", 1),
    ],
)
def test_every_specifier_becomes_an_ir_node(specifier, name, operands):
    statement = first(f"x = new Car {specifier}")
    spec = statement.value.specifiers[0]
    assert (spec.name, len(spec.operands)) == (name, operands)


@pytest.mark.parametrize(
    ("text", "message", "line", "column"),
    [
        ("import math\n", "imports are not supported", 1, 1),
        ("ego = new Car\ndef f():\n    pass\n", "function definitions are not supported", 2, 1),
        ("ego = new Car\nclass A:\n    pass\n", "class definitions are not supported", 2, 1),
        ("x = ego.lane.centerline.pointAlongBy(3)\n", "no method calls", 1, 5),
        ("x = [i for i in range(3)]\n", "not supported", 1, 5),
        ("ego = new Car above ego\n", "3-D specifiers", 1, 15),
        ("while True:\n    pass\n", "while loops are not supported", 1, 1),
        ("for i in [1, 2]:\n    pass\n", "only loops of the form", 1, 1),
        ("ego = new Car on\n", "Scenic syntax error", 1, 17),
        ("behavior B():\n    if True:\n        wait\n", "'if' is not supported in a behaviour", 2, 5),
        ("behavior B():\n    do A(), C()\n", "several behaviours at once", 2, 5),
        ("behavior B():\n    do choose A(), C()\n", "'do choose' is not supported", 2, 5),
    ],
)
def test_unsupported_constructs_are_rejected_with_their_place(text, message, line, column):
    with pytest.raises(UserError) as caught:
        parse_program(text, "bad.scenic")
    error = caught.value
    assert message in error.message
    assert (error.location.source, error.location.line, error.location.column) == ("bad.scenic", line, column)
    assert "\n" not in error.one_line()


@pytest.mark.parametrize(
    ("text", "message", "line"),
    [
        ("ego = new Car\nc = new Truk\n", "unknown class 'Truk'", 2),
        ("ego = new Car at (0, 0), at (1, 1)\n", "specifier 'at' is used twice", 1),
        ("ego = new Car\nc = new Car at (0, 0), offset by (1, 1)\n", "'position' is specified twice", 2),
        ("ego = new Car on roads\n", "unknown name 'roads'", 1),
        ("c = new Car ahead of ego\n", "ego is used before it is defined", 1),
        ("ego = new Car\nfor i in range(Range(1, 2)):\n    new Car\n", "constant whole number", 2),
        ("ego = new Car\nrequire ego\n", "expected a condition", 2),
        ("model scenic.simulators.gta.model\nego = new Car\n", "unknown world model", 1),
        ("c = new Car\n", "defines no ego", None),
        ("ego = new Car facing toward 3\n", "expected a vector", 1),
        ("ego = new Car\nx = ego.color\n", "no property 'color'", 2),
        ("ego = new Car\nx = Range(5, 1)\n", "low <= high", 2),
    ],
)
def test_resolution_errors_name_the_line(text, message, line):
    with pytest.raises(UserError) as caught:
        compile_scene(text, "bad.scenic")
    assert message in caught.value.message
    assert caught.value.location.line == line


def test_dependency_order_of_the_papers_examples():
    fig3 = compile_scene(
        HEADER + "ego = new Car on road\notherCar = new Car ahead of ego by Range(4, 10)\n"
        "require not (otherCar in intersection)",
        "fig3.scenic",
    )
    features = [[repr(f) for f in g.features] for g in fig3.groups if g.features]
    assert features == [["ego.x", "ego.y"], ["ego.heading"], ["otherCar.x", "otherCar.y"], ["otherCar.heading"]]
    fig6 = compile_scene(
        HEADER + "spot = new OrientedPoint on curb\nego = new Car at (spot offset by (Range(2, 4), Range(5, 10)))\n"
        "sideCar = new Car left of spot by Range(1, 3)",
        "fig6.scenic",
    )
    groups = [g for g in analyse(fig6.program) if g.features]
    # ego's and sideCar's positions share spot (jointly dependent), and so does sideCar's heading
    # (left of spot takes spot's orientation); ego's heading depends only on ego's position
    assert [sorted(repr(f) for f in g.features) for g in groups] == [
        ["ego.x", "ego.y", "sideCar.heading", "sideCar.x", "sideCar.y"],
        ["ego.heading"],
    ]
    assert groups[0].introduces == ["ego", "sideCar"]


def test_the_parser_loads_without_importing_scenic():
    code = (
        "import sys; from scenegrep.scenic.adapter import parse_program; "
        "parse_program('ego = new Car ahead of x by Range(1, 2)', 'x'); "
        "print(sorted(m for m in sys.modules if m == 'scenic' or m.startswith('scenic.')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_adapter_reads_every_field_of_the_scenic_nodes_it_maps():
    """A field the adapter did not read would be a silently dropped operand: each Scenic specifier and
    operator node class it maps lists exactly the node's fields."""
    import scenic.syntax.ast as scenic_ast

    from scenegrep.scenic.adapter import _OPERATOR_FIELDS, _SPECIFIER_FIELDS

    for kind, (_, fields) in {**_SPECIFIER_FIELDS, **_OPERATOR_FIELDS}.items():
        assert set(getattr(scenic_ast, kind)._fields) == set(fields), kind
