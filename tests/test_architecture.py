"""The package's imports point one way: no import circles, and no layer imports a higher one.

Every module under ``src/scenegrep`` is parsed (not imported) and every import it holds counts:
at module level, inside functions (a deferred import that dodges a circle is still a circle),
under ``if TYPE_CHECKING``, relative or absolute. ``from P import name`` is an import of the
module ``P.name`` when there is one, else of ``P``. A call of ``importlib.import_module`` or
``lazy_import`` with a constant name imports that module; with a computed name (a dispatcher
such as :func:`scenegrep.readers.module` or the CLI's command table) it may import any module
of the caller's package, so it counts as importing all of them. Importing ``a.b.c`` also runs
``a/__init__`` and ``a/b/__init__``; those implicit parent imports do not count (a package's
``__init__`` may re-export its modules).

:data:`LAYERS` orders the package's top-level units (subpackages and modules), lowest first. A
unit may import units of lower layers only; units that share a layer are independent of each
other. :data:`SCENE_LAYERS` orders the scene package's modules likewise (the map in its
``__init__``), but a module may import others of its own group there.
"""

from __future__ import annotations

import ast
import importlib.machinery
from collections.abc import Iterable, Mapping
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
PACKAGE = "scenegrep"

LAYERS: tuple[tuple[str, ...], ...] = (
    ("errors", "cache", "lazy", "progress", "json_lines", "wording"),  # foundations: import nothing of scenegrep
    ("model", "terminal"),  # the data model (label traces, road maps); text safe for terminals
    ("writers",),  # the model to files
    ("readers",),  # files to the model (converted maps are cached through the writers)
    ("spre", "label", "scenic", "summary"),  # SpRE; behaviour labelling; Scenic front end; `info`
    ("scene",),  # Scenic scene queries (on the Scenic front end, maps through the readers)
    ("scenario", "synth"),  # scenario queries and Scenic-generated data, both on scene queries
    ("dataset",),  # the engine over many traces: ingest, catalog, queries, exports
    ("view", "streams", ""),  # pictures and pages of results; queries over streams as read; "" is scenegrep/__init__
    ("cli",),  # the command line: thin faces over all of the above
    ("__main__",),  # python -m scenegrep
)
"""Top-level units of ``scenegrep``, lowest layer first (README, "Development")."""

SCENE_LAYERS: tuple[tuple[str, ...], ...] = (
    ("terms", "regions", "values", "vectors", "domain", "program"),  # the term language
    (
        "geometry",
        "shapes",
        "unknown",
        "follow",
        "follow_pieces",
        "follow_regions",
        "follow_inverse",
        "heading_index",
        "clip",
        "_reach",
    ),  # map geometry
    ("context", "expressions", "specifiers", "lenient_boxes", "resolve", "needs"),  # syntax, specifier semantics
    ("dependencies", "randoms", "evaluate"),  # analysis and evaluation
    ("tolerance", "decide", "solvers"),  # the decision procedures
    ("match", "query", "explain", "projection", "misses", "profiles", "vocabulary"),  # the match driver
    ("",),  # scene/__init__: the API
)
"""Modules (and the ``solvers`` subpackage) of ``scenegrep.scene``, lowest group first (its ``__init__``)."""

Graph = Mapping[str, Iterable[str]]


# ---------------------------------------------------------------------------- the import graph
def modules(root: Path, package: str) -> dict[str, Path]:
    """Every module of the package under ``root`` (the folder holding the package): dotted name ->
    file (a package is its ``__init__.py``; a C extension, its source or built file, counts as a
    module that imports nothing of the package)."""
    found = {}
    suffixes = (".c", *importlib.machinery.EXTENSION_SUFFIXES)
    for path in sorted((root / package).rglob("*")):
        if path.suffix == ".py":
            parts = path.relative_to(root).with_suffix("").parts
            found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
        elif path.name.endswith(suffixes):
            stem = path.name.split(".", 1)[0]
            found.setdefault(".".join((*path.parent.relative_to(root).parts, stem)), path)
    return found


def _known(name: str, names: Mapping[str, Path]) -> str | None:
    """The longest prefix of a dotted name that is a module of ``names``."""
    while name and name not in names:
        name = name.rpartition(".")[0]
    return name or None


def _from_target(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    """The absolute module name a ``from ... import`` reads from."""
    if not node.level:
        return node.module or ""
    base = module.split(".") if is_package else module.split(".")[:-1]
    base = base[: len(base) - node.level + 1]
    return ".".join([*base, node.module] if node.module else base)


def _dynamic_call(node: ast.AST) -> ast.expr | None:
    """The name argument of ``importlib.import_module(...)`` or ``lazy_import(...)``, else None."""
    if not isinstance(node, ast.Call) or not node.args:
        return None
    func = node.func
    name = func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""
    return node.args[0] if name in ("import_module", "lazy_import") else None


def imports_of(module: str, path: Path, names: Mapping[str, Path]) -> set[str]:
    """The modules of ``names`` that ``module`` (its file at ``path``) imports (see the module
    docstring), itself excluded."""
    if path.suffix != ".py":
        return set()
    is_package = path.name == "__init__.py"
    package = module if is_package else module.rpartition(".")[0]
    found: set[str | None] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(_known(alias.name, names) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            source = _from_target(module, is_package, node)
            for alias in node.names:
                inner = f"{source}.{alias.name}"
                found.add(inner if inner in names else _known(source, names))
        elif (argument := _dynamic_call(node)) is not None:
            if isinstance(argument, ast.Constant) and isinstance(argument.value, str):
                found.add(_known(argument.value, names))
            else:
                found.update(n for n in names if n.startswith(f"{package}."))
    return {n for n in found if n is not None and n != module}


def import_graph(root: Path = SRC, package: str = PACKAGE) -> dict[str, set[str]]:
    """Module -> the modules of the package it imports."""
    names = modules(root, package)
    return {module: imports_of(module, path, names) for module, path in names.items()}


# ---------------------------------------------------------------------------- the checks
def cycles(graph: Graph) -> list[list[str]]:
    """One circle per strongly connected component of more than one module, as a path that
    returns to its first module (``[a, b, a]``); none when the imports point one way."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    components: list[set[str]] = []

    def visit(start: str) -> None:  # Tarjan's algorithm, iterative (import chains run deep)
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, successors = work[-1]
            for succ in successors:
                if succ not in index:
                    index[succ] = low[succ] = len(index)
                    stack.append(succ)
                    on_stack.add(succ)
                    work.append((succ, iter(sorted(graph.get(succ, ())))))
                    break
                if succ in on_stack:
                    low[node] = min(low[node], index[succ])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = set()
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.add(member)
                        if member == node:
                            break
                    components.append(component)

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return [_circle_in(graph, c) for c in components if len(c) > 1]


def _circle_in(graph: Graph, component: set[str]) -> list[str]:
    """A shortest circle through the component's first module (breadth-first within it)."""
    first = min(component)
    parent: dict[str, str] = {}
    frontier = [first]
    while frontier:
        following = []
        for node in frontier:
            for succ in sorted(graph.get(node, ())):
                if succ == first:
                    path = [node]
                    while path[-1] != first:
                        path.append(parent[path[-1]])
                    return [first, *reversed(path[:-1]), first]
                if succ in component and succ not in parent:
                    parent[succ] = node
                    following.append(succ)
        frontier = following
    raise AssertionError(f"no circle through {first}")  # a strongly connected component has one


def unit_of(module: str, package: str = PACKAGE) -> str | None:
    """The top-level unit of a module of ``package``: ``scenegrep.scene.solvers.walk`` ->
    ``scene`` (in ``scenegrep.scene``: ``solvers``); the package itself -> ``""``; None outside it."""
    if module == package:
        return ""
    return module[len(package) + 1 :].split(".")[0] if module.startswith(f"{package}.") else None


def layer_violations(
    graph: Graph, layers: tuple[tuple[str, ...], ...] = LAYERS, package: str = PACKAGE, peers: bool = False
) -> list[str]:
    """Every import between the units of ``package`` (:func:`unit_of`) from a unit of a higher
    layer, or of the same layer unless ``peers`` allows that, and every unit missing from the
    layers, as messages. Imports of modules outside ``package`` are not looked at."""
    rank = {unit: level for level, units in enumerate(layers) for unit in units}
    units = {m: unit_of(m, package) for m in graph}
    problems = sorted(
        {f"{u!r} has no layer in {package}'s layers" for u in units.values() if u not in rank | {None: 0}}
    )
    for module, targets in sorted(graph.items()):
        for target in sorted(targets):
            a, b = units[module], unit_of(target, package)
            if a is None or b is None or a == b or a not in rank or b not in rank:
                continue
            if rank[b] > rank[a] or (rank[b] == rank[a] and not peers):
                how = "in the same layer as" if rank[b] == rank[a] else "in a higher layer than"
                problems.append(f"{module} imports {target}: {b!r} is {how} {a!r}")
    return problems


# ---------------------------------------------------------------------------- the tests
@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    return import_graph()


def test_the_package_is_walked(graph):
    assert {"scenegrep", "scenegrep.cli.main", "scenegrep.scene.decide", "scenegrep.readers._strem"} <= set(graph)
    assert "scenegrep.scene.solvers" in graph["scenegrep.scene.decide"]


def test_no_import_circles(graph):
    found = cycles(graph)
    assert not found, "import circles:\n" + "\n".join(" -> ".join(c) for c in found)


def test_imports_point_down_the_layers(graph):
    problems = layer_violations(graph)
    assert not problems, "\n".join(problems)


def test_scene_modules_import_their_own_group_or_lower_ones(graph):
    problems = layer_violations(graph, SCENE_LAYERS, f"{PACKAGE}.scene", peers=True)
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize(("layers", "package"), [(LAYERS, PACKAGE), (SCENE_LAYERS, f"{PACKAGE}.scene")])
def test_every_layer_names_real_units(graph, layers, package):
    units = {unit_of(m, package) for m in graph} - {None}
    listed = [u for layer in layers for u in layer]
    assert len(listed) == len(set(listed))
    assert set(listed) == units


def test_the_checks_fail_on_a_circle_and_on_an_upward_import():
    fake = {
        "scenegrep.model": {"scenegrep.errors"},
        "scenegrep.errors": set(),
        "scenegrep.scene.a": {"scenegrep.scene.b", "scenegrep.model"},
        "scenegrep.scene.b": {"scenegrep.scene.c"},
        "scenegrep.scene.c": {"scenegrep.scene.a", "scenegrep.dataset"},  # upward
        "scenegrep.dataset": {"scenegrep.scene.a"},
        "scenegrep.spre": {"scenegrep.label"},  # a peer
        "scenegrep.label": set(),
        "scenegrep.nowhere": set(),  # no layer
    }
    assert cycles(fake) == [
        ["scenegrep.dataset", "scenegrep.scene.a", "scenegrep.scene.b", "scenegrep.scene.c", "scenegrep.dataset"]
    ]
    assert layer_violations(fake) == [
        "'nowhere' has no layer in scenegrep's layers",
        "scenegrep.scene.c imports scenegrep.dataset: 'dataset' is in a higher layer than 'scene'",
        "scenegrep.spre imports scenegrep.label: 'label' is in the same layer as 'spre'",
    ]
    fake["scenegrep.scene.c"] = {"scenegrep.model"}
    fake["scenegrep.spre"] = {"scenegrep.errors"}
    del fake["scenegrep.nowhere"]
    assert cycles(fake) == []
    assert layer_violations(fake) == []


def test_the_check_within_a_package_lets_a_group_import_itself_only_when_asked():
    inner = {
        "scenegrep.scene.a": {"scenegrep.scene.b"},
        "scenegrep.scene.b": {"scenegrep.scene.c", "scenegrep.model"},  # model: outside the package
        "scenegrep.scene.c": set(),
    }
    upward = "scenegrep.scene.b imports scenegrep.scene.c: 'c' is in a higher layer than 'b'"
    layers = (("a", "b"), ("c",))
    assert layer_violations(inner, layers, "scenegrep.scene", peers=True) == [upward]
    assert layer_violations(inner, layers, "scenegrep.scene") == [
        "scenegrep.scene.a imports scenegrep.scene.b: 'b' is in the same layer as 'a'",
        upward,
    ]
    assert layer_violations(inner, (("a",), ("c",)), "scenegrep.scene", peers=True) == [
        "'b' has no layer in scenegrep.scene's layers"
    ]


def test_the_walker_sees_every_kind_of_import(tmp_path):
    files = {
        "pkg/__init__.py": "from .a import thing\n",
        "pkg/a.py": (
            "from typing import TYPE_CHECKING\nimport os\n"
            "if TYPE_CHECKING:\n    from pkg.sub import deep\n"
            "def f():\n    from . import b\n    import pkg.sub.c\n"
        ),
        "pkg/b.py": "from .sub.c import name\nfrom . import thing\n",
        "pkg/sub/__init__.py": (
            "import importlib\ndef load(n):\n    return importlib.import_module(f'{__package__}.{n}')\n"
        ),
        "pkg/sub/c.py": (
            "from ..sub import deep\nfrom scenegrep.lazy import lazy_import\nx = lazy_import('pkg.sub._ext')\n"
        ),
        "pkg/sub/deep.py": "",
        "pkg/sub/_ext.c": "",
    }
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    assert import_graph(tmp_path, "pkg") == {
        "pkg": {"pkg.a"},
        "pkg.a": {"pkg.sub.deep", "pkg.b", "pkg.sub.c"},  # TYPE_CHECKING, deferred relative, deferred absolute
        "pkg.b": {"pkg.sub.c", "pkg"},  # a name of a package's __init__ is an import of the package
        "pkg.sub": {"pkg.sub.c", "pkg.sub.deep", "pkg.sub._ext"},  # a computed name: any module of the package
        "pkg.sub.c": {"pkg.sub.deep", "pkg.sub._ext"},  # relative from a package; lazy_import of a constant
        "pkg.sub.deep": set(),
        "pkg.sub._ext": set(),
    }
    assert cycles(import_graph(tmp_path, "pkg")) == [["pkg", "pkg.a", "pkg.b", "pkg"]]
