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
import sys
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


def parse_scenic(text: str, filename: str) -> ast.Module:
    """Parse Scenic source text with Scenic's parser; syntax errors become one-line :class:`UserError`."""
    try:
        return scenic_parser().parse_string(text, "exec", filename=filename)
    except Exception as error:  # Scenic raises its own ScenicParseError (or our stand-in)
        raise _syntax_error(error, filename) from None


def _syntax_error(error: Exception, filename: str) -> UserError:
    inner: Any = getattr(error, "error", error)
    line = getattr(inner, "lineno", None)
    column = getattr(inner, "offset", None)
    message = getattr(inner, "msg", None) or str(error) or type(error).__name__
    return UserError(f"Scenic syntax error: {message}", at(filename, line, column))
