"""Hopcroft–Karp maximum bipartite matching: can every program object take a distinct label object?"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable, Mapping, Sequence

INF = float("inf")


def maximum_matching(edges: Mapping[Hashable, Sequence[Hashable]]) -> dict[Hashable, Hashable]:
    """A maximum matching of left vertices (keys) to right vertices (their candidate lists),
    as left -> right; O(E·sqrt(V)) (Hopcroft and Karp, 1973)."""
    left = list(edges)
    match_left: dict[Hashable, Hashable] = {}
    match_right: dict[Hashable, Hashable] = {}
    distance: dict[Hashable, float] = {}

    def layers() -> bool:
        queue: deque[Hashable] = deque()
        for u in left:
            distance[u] = 0 if u not in match_left else INF
            if u not in match_left:
                queue.append(u)
        found = False
        while queue:
            u = queue.popleft()
            for v in edges[u]:
                w = match_right.get(v)
                if w is None:
                    found = True
                elif distance[w] == INF:
                    distance[w] = distance[u] + 1
                    queue.append(w)
        return found

    def augment(u: Hashable) -> bool:
        for v in edges[u]:
            w = match_right.get(v)
            if w is None or (distance[w] == distance[u] + 1 and augment(w)):
                match_left[u], match_right[v] = v, u
                return True
        distance[u] = INF
        return False

    while layers():
        for u in left:
            if u not in match_left:
                augment(u)
    return match_left
