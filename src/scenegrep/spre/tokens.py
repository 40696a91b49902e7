"""Lexing SpRE text into tokens, in scenegrep's syntax or STREM v0.2.0's.

Both lexers skip space, tab, CR and LF and reject non-ASCII text. They differ on
the rest:

- scenegrep's lexer knows the paper's angle keywords (``<nonempty>``, ``<exists>``, ``<x>``,
  ...), ``+ ? . ~ ^ == !=``, quoted strings and reals such as ``.5`` or ``1e3``, and
  rejects any other character;
- STREM's lexer (``--compat strem``) knows only its own tokens and drops every other
  character *with a warning* (docs/strem-reference.md §3), as STREM does.
"""

from __future__ import annotations

import functools
import json
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

from ..errors import UserError
from .errors import query_error

T = TypeVar("T")

ANGLE_KEYWORDS = frozenset(
    {
        "nonempty",
        "exists",
        "forall",
        "subset",
        "interior",
        "closure",
        "frontof",
        "behind",
        "leftof",
        "rightof",
        "above",
        "below",
        "x",
        "y",
        "z",
        "dist",
        "area",
        "width",
        "height",
        "gap",
        "iou",
        "score",
        "speed",
    }
)
"""Words written between angle brackets in the paper's notation (``<nonempty>``, ``<x>``)."""

STREM_KEYWORDS = frozenset({"NE", "E", "A"})


@dataclass(frozen=True)
class Token:
    """A token: its kind (the symbol itself for punctuation, or INT, REAL, IDENT, STRING,
    ANGLE, KEYWORD, END), its text and its span in the query."""

    kind: str
    text: str
    start: int
    end: int


_PUNCTUATION = ":= <= >= == != ( ) { } [ ] , : * + ? . | & ! ~ @ - / ^ < > % =".split()
_STREM_PUNCTUATION = ":= <= >= ( ) { } [ ] , : * % ! & | @ - + / < >".split()

_SCENEGREP = re.compile(
    r"""
    (?P<ws>[ \t\r\n]+)
  | (?P<REAL>(?:[0-9]+\.[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|[0-9]+[eE][+-]?[0-9]+)
  | (?P<INT>[0-9]+)
  | (?P<ANGLE><(?:"""
    + "|".join(sorted(ANGLE_KEYWORDS, key=len, reverse=True))
    + r""")>)
  | (?P<IDENT>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<STRING>"(?:[^"\\\n]|\\.)*")
  | (?P<PUNCT>"""
    + "|".join(re.escape(p) for p in _PUNCTUATION)
    + r""")
""",
    re.VERBOSE,
)

_STREM = re.compile(
    r"""
    (?P<ws>[ \t\r\n]+)
  | (?P<REAL>[0-9]+\.[0-9]*)
  | (?P<INT>[0-9]+)
  | (?P<IDENT>[A-Za-z_][A-Za-z0-9_]*)
  | (?P<PUNCT>"""
    + "|".join(re.escape(p) for p in _STREM_PUNCTUATION)
    + r""")
""",
    re.VERBOSE,
)


def _check_ascii(text: str, source: str) -> None:
    for i, char in enumerate(text):
        if ord(char) > 127:
            raise query_error(
                f"non-ASCII character {char!r} (U+{ord(char):04X}); SpREs are ASCII", text, i, i + 1, source
            )


def tokenize(text: str, source: str = "<query>") -> list[Token]:
    """Tokens of scenegrep's syntax, ending with an END token; UserError at the first bad character."""
    _check_ascii(text, source)
    tokens, pos = [], 0
    while pos < len(text):
        found = _SCENEGREP.match(text, pos)
        if found is None:
            raise query_error(f"unexpected character {text[pos]!r}", text, pos, pos + 1, source)
        kind = found.lastgroup or ""
        if kind != "ws":
            value = found.group()
            tokens.append(Token(value if kind == "PUNCT" else kind, value, pos, found.end()))
        pos = found.end()
    tokens.append(Token("END", "", len(text), len(text)))
    return tokens


def tokenize_strem(text: str, source: str = "<query>") -> tuple[list[Token], list[str]]:
    """Tokens of STREM v0.2.0's syntax and the warnings for the characters it drops."""
    _check_ascii(text, source)
    tokens, warnings, pos = [], [], 0
    while pos < len(text):
        found = _STREM.match(text, pos)
        if found is None:
            warnings.append(f"ignoring unrecognized character `{text[pos]}` at {source}:{_place(text, pos)}")
            pos += 1
            continue
        kind = found.lastgroup or ""
        if kind != "ws":
            value = found.group()
            if kind == "IDENT" and value in STREM_KEYWORDS:
                kind = "KEYWORD"
            tokens.append(Token(value if kind == "PUNCT" else kind, value, pos, found.end()))
        pos = found.end()
    tokens.append(Token("END", "", len(text), len(text)))
    return tokens, warnings


MAX_NESTING = 100
"""The deepest a query may nest: groups, prefix operators, quantifiers, track binders (and, in
STREM's right-associative grammar, chained operators)."""

MAX_POSITIONS = 20_000
"""Largest automaton (letter occurrences after expanding repetitions) a query may compile to; also
the largest repetition count. A frame costs up to this many position steps."""

MAX_CHARACTERS = 100_000
"""Longest query text (parsing costs about 10 µs per character)."""

MAX_NODES = 10_000
"""Most syntax nodes (letters, operators, terms, numbers) a query may have."""

TOO_DEEP = f"the query nests more than {MAX_NESTING} levels deep (groups, operators, quantifiers)"


class TooDeep(UserError):
    """A query nested beyond :data:`MAX_NESTING`; never backtracked over."""


def nested(parse: Callable[..., T]) -> Callable[..., T]:
    """Decorates a parser method through which the grammar recurses: more than :data:`MAX_NESTING`
    of them active at once is a :class:`TooDeep` error at the current token (before Python's stack
    runs out)."""

    @functools.wraps(parse)
    def guarded(self: Cursor, *args: Any) -> T:
        if self.depth >= MAX_NESTING:
            error = self.error(TOO_DEEP)
            raise TooDeep(error.message, error.location, error.detail)
        self.depth += 1
        try:
            return parse(self, *args)
        finally:
            self.depth -= 1

    return guarded


class Cursor:
    """A position in a token list, with the helpers both parsers use."""

    def __init__(self, text: str, source: str, tokens: list[Token]):
        self.text, self.source, self.tokens, self.pos = text, source, tokens, 0
        self.depth = 0

    @property
    def token(self) -> Token:
        return self.tokens[self.pos]

    def at(self, *kinds: str) -> bool:
        return self.token.kind in kinds

    def take(self) -> Token:
        token = self.token
        self.pos += 1
        return token

    def error(self, message: str, token: Token | None = None) -> UserError:
        """A query error at a token (the current one by default)."""
        token = token or self.token
        return query_error(message, self.text, token.start, max(token.end, token.start + 1), self.source)

    def expect(self, kind: str, what: str) -> Token:
        if not self.at(kind):
            found = "the end of the query" if self.at("END") else repr(self.token.text)
            raise self.error(f"expected {what} but found {found}")
        return self.take()

    def count(self, what: str = "a repetition count") -> int:
        """A repetition count (an INT token, ``what`` in the error if absent), at most :data:`MAX_POSITIONS`."""
        token = self.expect("INT", what)
        if len(token.text) > len(str(MAX_POSITIONS)) or int(token.text) > MAX_POSITIONS:
            raise self.error(f"repetition count {token.text[:12]} is above the limit of {MAX_POSITIONS}", token)
        return int(token.text)

    def span(self, start: Token) -> tuple[int, int]:
        """From the start of ``start`` to the end of the last token taken."""
        return (start.start, self.tokens[self.pos - 1].end)


def _place(text: str, offset: int) -> str:
    line = text.count("\n", 0, offset) + 1
    return f"{line}:{offset - (text.rfind(chr(10), 0, offset) + 1) + 1}"


def unquote(token: Token, text: str, source: str) -> str:
    """The value of a STRING token (JSON escapes)."""
    try:
        return str(json.loads(token.text))
    except json.JSONDecodeError:
        raise query_error(f"bad string literal {token.text}", text, token.start, token.end, source) from None
