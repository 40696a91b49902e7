"""Parsing: standard precedence (default), STREM's flat right-associative precedence
(--compat strem), the paper's notation, and errors with line:column and a caret."""

import pytest

from scenegrep.errors import UserError
from scenegrep.spre import compile_query
from scenegrep.spre import syntax as s
from scenegrep.spre.parser import parse
from scenegrep.spre.strem_parser import parse_strem

CAR, PED, BUS = (s.Letter(s.Present(s.ClassAtom(c))) for c in ("car", "ped", "bus"))


def present(name: str) -> s.Present:
    return s.Present(s.ClassAtom(name))


def test_regex_precedence_standard_and_strem():
    assert parse("[[:car:]][[:ped:]]|[[:bus:]]") == s.Alternation((s.Concat((CAR, PED)), BUS))
    assert parse_strem("[[:car:]][[:ped:]]|[[:bus:]]")[0] == s.Concat((CAR, s.Alternation((PED, BUS))))
    assert parse("[[:car:]]|[[:ped:]][[:bus:]]") == s.Alternation((CAR, s.Concat((PED, BUS))))
    assert parse("[[:car:]][[:ped:]]*") == s.Concat((CAR, s.Repeat(PED, 0, None)))
    assert parse("[[:car:]]{2}{3}") == s.Repeat(s.Repeat(CAR, 2, 2), 3, 3)


def test_formula_precedence_standard_and_strem():
    standard = parse("[[:car:] & [:ped:] | [:bus:]]").formula
    assert standard == s.Or(s.And(present("car"), present("ped")), present("bus"))
    strem = parse_strem("[[:car:] & [:ped:] | [:bus:]]")[0].formula
    assert strem == s.And(present("car"), s.Or(present("ped"), present("bus")))
    assert parse("[![:car:] & [:ped:]]").formula == s.And(s.Not(present("car")), present("ped"))
    assert parse_strem("[![:car:] & [:ped:]]")[0].formula == s.Not(s.And(present("car"), present("ped")))
    assert parse_strem("[NE [:car:] & [:ped:]]")[0].formula == s.And(s.NonEmpty(s.ClassAtom("car")), present("ped"))


def _value(metric: s.Metric) -> float:
    match metric:
        case s.Number(v):
            return v
        case s.Negate(m):
            return -_value(m)
        case s.Arithmetic(op, a, b):
            return {
                "+": a and _value(a) + _value(b),
                "-": _value(a) - _value(b),
                "*": _value(a) * _value(b),
                "/": _value(a) / _value(b),
                "^": _value(a) ** _value(b),
            }[op]


@pytest.mark.parametrize(
    "expression, standard, strem",
    [
        ("8 - 4 - 2", 2.0, 6.0),
        ("2 * 3 + 4", 10.0, 14.0),
        ("-1 + 2", 1.0, -3.0),
        ("2 ^ 3 ^ 2", 512.0, None),
    ],
)
def test_arithmetic(expression, standard, strem):
    assert _value(parse(f"[{expression} > 0]").formula.left) == standard
    if strem is not None:
        assert _value(parse_strem(f"[{expression} > 0]")[0].formula.left) == strem


def test_paper_notation_and_extensions():
    tree = parse("[<exists>(p := [:pedestrian:])(<x>(p) < 3 & <nonempty>(p & [:car:]))]+ .? [:bus:]{,2}")
    first, anything, buses = tree.items
    assert isinstance(first, s.Repeat) and (first.low, first.high) == (1, None)
    quantifier = first.item.formula
    assert quantifier.kind == "E" and quantifier.bindings[0].var == "p"
    assert isinstance(quantifier.body, s.And) and isinstance(quantifier.body.right, s.NonEmpty)
    assert anything == s.Repeat(s.AnyFrame(), 0, 1)
    assert buses == s.Repeat(BUS, 0, 2)
    assert parse("[[:car:] <subset> ~[:bus:]]").formula == s.Subset(
        s.ClassAtom("car"), s.Complement(s.ClassAtom("bus"))
    )
    assert parse("[[:car:] <= [:bus:]]").formula == s.Subset(s.ClassAtom("car"), s.ClassAtom("bus"))
    assert parse("[NE(I([:car:]) & C([:bus:]))]").formula == s.NonEmpty(
        s.Intersection(s.Interior(s.ClassAtom("car")), s.Closure(s.ClassAtom("bus")))
    )


def test_class_atoms_with_dotted_names_quotes_and_filters():
    atom = parse('[[:vehicle.car:score>=0.5,colour="dark red":]]').formula.term
    assert atom == s.ClassAtom("vehicle.car", (s.Filter("score", ">=", 0.5), s.Filter("colour", "=", "dark red")))
    assert parse("[[:traffic-light:]]").formula.term.name == "traffic-light"
    assert parse("[:car:]*") == s.Repeat(CAR, 0, None)


def test_spans_do_not_affect_equality():
    a, b = parse("[[:car:]][[:car:]]").items
    assert a == b and a.span != b.span and hash(a) == hash(b)


@pytest.mark.parametrize(
    "query, place, message",
    [
        ("[[:car:]]{3,1}", "1:10", "minimum above its maximum"),
        ("[@foo([:car:]) > 1]", "1:2", "unknown function @foo"),
        ("[@x([:car:], [:ped:]) > 1]", "1:2", "@x takes 1 argument, not 2"),
        ("[@x(v) > 1]", "1:5", "variable 'v' is not bound"),
        ("[[:car:] é]", "1:10", "non-ASCII character"),
        ("[[:car:] $ [:ped:]]", "1:10", "unexpected character '$'"),
        ("[[:car:]]\n[[:ped:] &]", "2:11", "expected a class"),
        ("[[:car:]", "1:9", "expected ']'"),
        ("[]", "1:2", "empty frame formula"),
        ("[[:car:] < 3]", "1:10", "compares numbers"),
    ],
)
def test_errors_have_place_and_caret(query, place, message):
    with pytest.raises(UserError) as info:
        compile_query(query)
    assert info.value.one_line().startswith(f"<query>:{place}: ")
    assert message in info.value.message
    line, column = (int(v) for v in place.split(":"))
    caret_line = info.value.detail.splitlines()[1]
    assert caret_line.index("^") - 2 == column - 1


@pytest.mark.parametrize(
    "query, message",
    [
        ("[[:car:]]+", "expected"),
        ("[[:car:]]{,2}", "expected an integer"),
        ("[NE v]", "expected"),
        ("[(@x([:car:])+1) > 3]", "expected a comparison"),
        ("[@w([:car:]) > 1]", "unknown function @w"),
        ("[NE(![:car:])]", "term complement"),
        ("[[:car:]]{2,1}", "minimum above"),
    ],
)
def test_strem_compat_rejects_what_strem_rejects_or_crashes_on(query, message):
    with pytest.raises(UserError, match=message):
        compile_query(query, compat=True)


def test_strem_compat_drops_unknown_characters_with_warnings():
    query = compile_query("[~[:car:]]?", compat=True)
    assert query.tree == CAR
    assert [w.split(" at ")[0] for w in query.warnings] == [
        "ignoring unrecognized character `~`",
        "ignoring unrecognized character `?`",
    ]


def test_strem_letter_limit():
    compile_query("[[:a:]]" * 52, compat=True)
    with pytest.raises(UserError, match="at most 52"):
        compile_query("[[:a:]]" * 53, compat=True)
    compile_query("[[:a:]]" * 53)
