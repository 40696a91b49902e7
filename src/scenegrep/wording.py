"""Wording of user-facing messages: counts with their noun (and verb) in the right number,
index ranges that are never ``(0 to -1)``, the article of a word, and lists of names.

``counted(1, "object")`` is ``1 object``, ``counted(2, "object")`` ``2 objects``;
``verb(1, "match")`` is ``matches``, ``verb(2, "be")`` ``are``; ``numbered(0, "match")`` is
``no matches``, ``numbered(3, "frame")`` ``3 frames (0 to 2)``; ``article("OpenDRIVE")`` is
``an``; ``listed(names)`` sorts and joins names, at most :data:`MAX_LISTED`. Every message
with a count goes through these.
"""

from __future__ import annotations

from collections.abc import Iterable

MAX_LISTED = 20
"""At most this many names are listed (then ``...``)."""

_IRREGULAR = {"child": "children", "person": "people", "this": "these", "axis": "axes"}

_VERBS = {"be": ("is", "are"), "have": ("has", "have"), "was": ("was", "were")}


def plural(noun: str, count: int = 2) -> str:
    """``noun`` in the number of ``count`` (English: ``-s``, ``-es`` after s/x/z/ch/sh, ``y`` ->
    ``ies`` after a consonant, a few irregular words; the last word of a phrase is inflected)."""
    if count == 1:
        return noun
    head, _, last = noun.rpartition(" ")
    if last in _IRREGULAR:
        word = _IRREGULAR[last]
    elif last.endswith(("s", "x", "z", "ch", "sh")):
        word = last + "es"
    elif last.endswith("y") and len(last) > 1 and last[-2] not in "aeiou":
        word = last[:-1] + "ies"
    else:
        word = last + "s"
    return f"{head} {word}" if head else word


def counted(count: int, noun: str) -> str:
    """``count`` and ``noun`` in its number: ``1 trace``, ``0 traces``, ``2 traces``."""
    return f"{count} {plural(noun, count)}"


def verb(count: int, base: str) -> str:
    """A present-tense verb agreeing with ``count`` things: ``verb(1, "match")`` ``matches``,
    ``verb(2, "match")`` ``match``; ``be`` and ``have`` give is/are and has/have, ``was`` was/were."""
    if base in _VERBS:
        return _VERBS[base][count != 1]
    return plural(base) if count == 1 else base


def numbered(count: int, noun: str) -> str:
    """``count`` things numbered from 0, with their range: ``no frames``, ``1 frame (0)``,
    ``3 frames (0 to 2)``."""
    if count <= 0:
        return f"no {plural(noun)}"
    return f"{counted(count, noun)} ({'0' if count == 1 else f'0 to {count - 1}'})"


def article(word: str) -> str:
    """``a`` or ``an`` before ``word``, by its sound for the words scenegrep writes (an OpenDRIVE,
    an MCAP, a CSV, a Parquet, a user)."""
    first = word[:1]
    if not first:
        return "a"
    if word[:2].isupper() or word.isupper():  # read letter by letter: an MCAP, a CSV (a STREM: a word)
        return "an" if first.upper() in "AEFHILMNORX" else "a"
    if word.lower().startswith(("uni", "use", "usu", "one", "eu")):
        return "a"
    return "an" if first.lower() in "aeiou" else "a"


def listed(names: Iterable[str]) -> str:
    """Names sorted and comma-separated, at most :data:`MAX_LISTED` (``none`` for none)."""
    ordered = sorted(names)
    if not ordered:
        return "none"
    more = ", ..." if len(ordered) > MAX_LISTED else ""
    return ", ".join(ordered[:MAX_LISTED]) + more
