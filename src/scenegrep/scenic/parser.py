"""Scenic's own parser (``scenic.syntax.parser.parse_string``), loaded fast.

Importing the ``scenic`` package costs about a second (it pulls in trimesh,
scipy and OpenCV), yet its PEG parser needs only ``pegen`` and two modules of the
installed wheel. Unless ``scenic`` is already imported, :func:`scenic_parser`
loads ``scenic/syntax/ast.py`` and ``scenic/syntax/parser.py`` under temporary
stand-in parent packages (about 20 ms) and then removes the stand-ins, so a later
``import scenic`` is unaffected. The node classes of the two loads differ, which
is why :mod:`.adapter` dispatches on class names.
"""

from __future__ import annotations

import ast
import importlib.util
import io
import sys
import tokenize
from functools import cache
from pathlib import Path
from types import ModuleType
from typing import Any

from ..errors import UserError, at

_PARENTS = ("scenic", "scenic.syntax", "scenic.core")
_LOADED = ("scenic.core.errors", "scenic.syntax.ast", "scenic.syntax.parser")


class _StandInParseError(Exception):
    """Stands in for ``scenic.core.errors.ScenicParseError``: wraps the SyntaxError it is given."""

    def __init__(self, error: SyntaxError):
        self.error = error
        super().__init__(error.msg if isinstance(error, SyntaxError) else str(error))


def _load_module(name: str, path: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def _light_load(root: Path) -> ModuleType:
    saved = {name: sys.modules.get(name) for name in _PARENTS + _LOADED}
    try:
        for name in _PARENTS:
            package = ModuleType(name)
            package.__path__ = [str(root.joinpath(*name.split(".")[1:]))]
            sys.modules[name] = package
        errors = ModuleType("scenic.core.errors")
        errors.ScenicParseError = _StandInParseError  # type: ignore[attr-defined]
        sys.modules["scenic.core.errors"] = errors
        sys.modules["scenic.syntax"].ast = _load_module("scenic.syntax.ast", root / "syntax" / "ast.py")  # type: ignore[attr-defined]
        return _load_module("scenic.syntax.parser", root / "syntax" / "parser.py")
    finally:
        for name, module in saved.items():
            if module is None:
                sys.modules.pop(name, None)
            else:
                sys.modules[name] = module


@cache
def scenic_parser() -> ModuleType:
    """The module ``scenic.syntax.parser``, from the imported package if any, else light-loaded."""
    if "scenic" in sys.modules:
        import scenic.syntax.parser

        return scenic.syntax.parser
    spec = importlib.util.find_spec("scenic")
    if spec is None or not spec.submodule_search_locations:
        raise UserError("the scenic package is not installed (pip install scenic==3.1.1)")
    return _light_load(Path(next(iter(spec.submodule_search_locations))))


def read_program(path: str | Path) -> str:
    """The text of a ``.scenic`` file; a missing or unreadable file is a one-line :class:`UserError`."""
    try:
        return Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise UserError("no such file", at(path)) from None
    except (OSError, UnicodeDecodeError) as error:
        raise UserError(f"cannot read the program: {error}", at(path)) from None


MAX_TOKENS = 2_000
"""Most tokens a program may have (Scenic's parser takes about 1 ms per token; the largest
example program has under 400)."""

MAX_NESTING = 100
"""Deepest nesting of brackets, and of expressions in the parsed program (a chain of binary
operators nests one level per operator)."""

RECURSION_LIMIT = 20_000
"""Python's recursion limit while Scenic's (pure Python) parser runs: it needs about 25 frames
per bracket level."""


def parse_scenic(text: str, filename: str) -> ast.Module:
    """Parse Scenic source text with Scenic's parser after checking its size and nesting (see
    :data:`MAX_TOKENS`, :data:`MAX_NESTING`); syntax errors and programs over a limit become
    one-line :class:`UserError` at line:column."""
    _check_tokens(text, filename)
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, RECURSION_LIMIT))
    try:
        module = scenic_parser().parse_string(text, "exec", filename=filename)
    except Exception as error:  # Scenic raises its own ScenicParseError (or our stand-in)
        raise _syntax_error(error, filename) from None
    finally:
        sys.setrecursionlimit(limit)
    _check_depth(module, filename)
    return module


def _check_tokens(text: str, filename: str) -> None:
    """At most :data:`MAX_TOKENS` tokens and :data:`MAX_NESTING` levels of brackets, by Python's
    tokenizer (Scenic's lexical structure); text it cannot tokenize is left to Scenic's parser."""
    depth = 0
    try:
        for count, token in enumerate(tokenize.generate_tokens(io.StringIO(text).readline), 1):
            if count > MAX_TOKENS:
                raise _limit_error(f"the program has more than {MAX_TOKENS} tokens", token.start, filename)
            if token.type != tokenize.OP:
                continue
            if token.string in "([{":
                depth += 1
                if depth > MAX_NESTING:
                    raise _limit_error(f"brackets nest more than {MAX_NESTING} levels deep", token.start, filename)
            elif token.string in ")]}":
                depth -= 1
    except (tokenize.TokenError, SyntaxError):
        return


def _check_depth(module: ast.Module, filename: str) -> None:
    """No expression or statement nested more than :data:`MAX_NESTING` levels (found without recursion)."""
    stack: list[tuple[ast.AST, int, tuple[int, int]]] = [(module, 0, (1, 0))]
    while stack:
        node, depth, place = stack.pop()
        place = (node.lineno, node.col_offset) if hasattr(node, "lineno") else place
        if depth > MAX_NESTING:
            raise _limit_error(f"the program nests more than {MAX_NESTING} levels deep", place, filename)
        stack.extend((child, depth + 1, place) for child in ast.iter_child_nodes(node))


def _limit_error(message: str, place: tuple[int, int], filename: str) -> UserError:
    """A limit error at a (line, 0-based column) place."""
    return UserError(message, at(filename, place[0], place[1] + 1))


def _syntax_error(error: Exception, filename: str) -> UserError:
    inner: Any = getattr(error, "error", error)
    line = getattr(inner, "lineno", None)
    column = getattr(inner, "offset", None)
    message = getattr(inner, "msg", None) or str(error) or type(error).__name__
    return UserError(f"Scenic syntax error: {message}", at(filename, line, column))
