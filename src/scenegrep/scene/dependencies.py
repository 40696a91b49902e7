"""Dependency analysis (seed 003 §5.2.1): the features, sorted and grouped.

A feature *depends on* another when its term reads that feature's observed
label value. Features whose terms share an unobserved random value (a random
variable or random point that is not itself a feature, like the ``spot`` of
the paper's Fig. 6) are *jointly dependent* and are checked together, in one
:class:`Group`. A ``require`` joins the group whose random values it shares
(so soundness never rests on the paper's assumption that it shares none);
otherwise it is checked as soon as every label value it reads is available.
Groups are ordered so that each comes after the groups of the features it
reads (cycles, which Scenic itself rejects, are merged into one group), ties
broken by program order.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .program import Feature, Requirement, SceneProgram
from .terms import Term, leaf_dependencies

RANDOM_LEAVES = ("var", "choice", "point")


@dataclass(eq=False)
class Group:
    """Features checked together, the requirements checked with them, the program objects they
    first bring in (in order) and the random leaves they must find values for."""

    features: list[Feature] = field(default_factory=list)
    requirements: list[Requirement] = field(default_factory=list)
    introduces: list[str] = field(default_factory=list)
    unknowns: frozenset[Term] = frozenset()
    objects: frozenset[str] = frozenset()
    """Every program object whose features the group reads (its own and those its terms observe)."""

    def describe(self) -> str:
        parts = [repr(f) for f in self.features] + [r.description for r in self.requirements]
        return ", ".join(parts)


def random_leaves(term: Term) -> set[Term]:
    leaves = set(term.leaves())
    if term.op in RANDOM_LEAVES:
        leaves.add(term)
    return {leaf for leaf in leaves if leaf.op in RANDOM_LEAVES}


def _observed(term: Term) -> set[tuple[str, str]]:
    leaves = set(term.leaves()) | {term} | leaf_dependencies(term)
    return {leaf.value for leaf in leaves if leaf.op == "observed"}


class _UnionFind:
    def __init__(self, n: int):
        self.parent = list(range(n))

    def find(self, i: int) -> int:
        while self.parent[i] != i:
            self.parent[i] = self.parent[self.parent[i]]
            i = self.parent[i]
        return i

    def union(self, a: int, b: int) -> None:
        ra, rb = self.find(a), self.find(b)
        if ra != rb:
            self.parent[max(ra, rb)] = min(ra, rb)


def analyse(scene: SceneProgram, requirements: list[Requirement] | None = None) -> list[Group]:
    """The ordered groups of a scene program (see the module docstring). ``requirements``
    defaults to all of the program's hard requirements."""
    features = [f for obj in scene.objects for f in obj.features]
    chosen = [r for r in scene.requirements if not r.soft] if requirements is None else requirements
    items: list[Feature | Requirement] = [*features, *chosen]
    terms = [item.term if isinstance(item, Feature) else item.condition for item in items]
    randoms = [random_leaves(t) for t in terms]
    sets = _UnionFind(len(items))
    owner: dict[object, int] = {}
    for i, leaves in enumerate(randoms):
        for leaf in leaves:
            key = leaf.value[0] if leaf.op == "point" else leaf  # both coordinates of a random point
            if key in owner:
                sets.union(owner[key], i)
            else:
                owner[key] = i
    members: dict[int, list[int]] = {}
    for i in range(len(items)):
        members.setdefault(sets.find(i), []).append(i)
    provides = {(f.obj, f.name): sets.find(i) for i, f in enumerate(features)}
    reads = [
        _observed(t) | ({(item.obj, item.name)} if isinstance(item, Feature) else set())
        for item, t in zip(items, terms)
    ]
    needs = {
        root: {provides[o] for i in idx for o in reads[i] if o in provides} - {root} for root, idx in members.items()
    }
    order = _schedule(_topological(sorted(members), needs), needs, members, items)
    return _groups(order, members, items, reads, randoms, scene)


def _schedule(
    components: list[list[int]], needs: dict[int, set[int]], members: dict[int, list[int]], items: list
) -> list[list[int]]:
    """Components with features in dependency order, each requirement-only component placed right
    after the last component it reads from (checked as early as possible)."""
    has_feature = [any(isinstance(items[i], Feature) for root in c for i in members[root]) for c in components]
    order = [c for c, f in zip(components, has_feature) if f]
    position = {root: k for k, c in enumerate(order) for root in c}
    late: list[tuple[int, int, list[int]]] = []
    for n, (component, feature) in enumerate(zip(components, has_feature)):
        if not feature:
            after = max((position[d] for root in component for d in needs[root]), default=-1)
            late.append((after, n, component))
    for after, _, component in sorted(late, reverse=True):
        order.insert(after + 1, component)
    return order


def _topological(roots: list[int], needs: dict[int, set[int]]) -> list[list[int]]:
    """Strongly connected components of the 'needs' graph in dependency order (Tarjan), ties by root index."""
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    stack: list[int] = []
    on_stack: set[int] = set()
    components: list[list[int]] = []

    def visit(v: int) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(needs[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            components.append(sorted(component))

    for root in roots:
        if root not in index:
            visit(root)
    return components


def _groups(
    order: list[list[int]],
    members: dict[int, list[int]],
    items: list,
    reads: list[set[tuple[str, str]]],
    randoms: list[set[Term]],
    scene: SceneProgram,
) -> list[Group]:
    groups: list[Group] = []
    introduced: set[str] = set()
    object_order = {o.name: i for i, o in enumerate(scene.objects)}
    for component in order:
        group = Group()
        unknowns: set[Term] = set()
        for root in component:
            for i in members[root]:
                item = items[i]
                (group.features if isinstance(item, Feature) else group.requirements).append(item)
                unknowns |= randoms[i]
                scene_objects = [o for o in reads[i] if o[0] in object_order]
                for obj, _ in sorted(scene_objects, key=lambda o: object_order[o[0]]):
                    if obj not in introduced:
                        introduced.add(obj)
                        group.introduces.append(obj)
        group.unknowns = frozenset(unknowns)
        group.objects = frozenset(
            o for root in component for i in members[root] for o, _ in reads[i] if o in object_order
        )
        groups.append(group)
    return groups


def completed_groups(groups: list[Group], assigned: set[str], newest: str) -> list[Group]:
    """The groups a partial correspondence of ``assigned`` objects decides that involve ``newest``
    (or no object at all, when ``newest`` is the only one assigned), with ``introduces`` recomputed
    for that sub-list: checking them prunes the partial correspondence (seed 003's badOCs)."""
    chosen = [
        g for g in groups if g.objects <= assigned and (newest in g.objects or (not g.objects and assigned == {newest}))
    ]
    introduced: set[str] = set()
    restricted = []
    for group in chosen:
        new = [o for o in group.introduces if o not in introduced]
        new += sorted(group.objects - introduced - set(new))
        introduced.update(new)
        restricted.append(Group(group.features, group.requirements, new, group.unknowns, group.objects))
    return restricted
