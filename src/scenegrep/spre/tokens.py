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

import json
import re
from dataclasses import dataclass

from ..errors import UserError
from .errors import query_error

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


class Cursor:
    """A position in a token list, with the helpers both parsers use."""

    def __init__(self, text: str, source: str, tokens: list[Token]):
        self.text, self.source, self.tokens, self.pos = text, source, tokens, 0

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
