"""Command-line parsing conventions shared by every command.

- Options may come before or after positional arguments: each command's arguments are parsed
  with :meth:`argparse.ArgumentParser.parse_known_intermixed_args`, so
  ``scenegrep scenario PROG --window 3s DATA`` and ``scenegrep scenario PROG DATA --window 3s``
  are the same command line.
- A usage error is a :class:`~scenegrep.errors.UserError`: one line, exit code 2, placed at the
  command's name (``scenegrep: error: scene: ...``), never ``scenegrep scenegrep``.
- An unknown option names the command's nearest options (``did you mean --window?``, by
  :func:`difflib.get_close_matches`); an unknown command the nearest commands; a bad choice lists
  the valid ones (argparse's own message).
"""

from __future__ import annotations

import argparse
from collections.abc import Collection, Sequence

from ..errors import UserError, at, nearest

PROGRAM = "scenegrep"


class CommandParser(argparse.ArgumentParser):
    """An argument parser whose usage errors are user errors (one line, exit 2), placed at the
    command's name, and whose leftover arguments are reported with the nearest options."""

    def error(self, message: str) -> None:  # type: ignore[override]
        place = self.prog.removeprefix(PROGRAM).strip()
        raise UserError(message, at(place) if place else None)

    def parse_command(self, argv: Sequence[str]) -> argparse.Namespace:
        """The arguments of this command, options and positionals in any order; UserError for
        anything left over (see :func:`leftover_text`). Every argument after ``--`` is positional
        (argparse's intermixed parsing drops them: they are parsed as placeholders, then put back)."""
        unknown = first_unknown_option(argv, self._option_string_actions)
        if unknown is not None:  # before any other error (a misspelt required option is reported as such)
            self.error(leftover_text([unknown], option_strings(self)))
        argv, dashed = _hide_dashed(argv)
        args, extras = self.parse_known_intermixed_args(argv)
        if extras:
            self.error(leftover_text([dashed.get(extra, extra) for extra in extras], option_strings(self)))
        for name, value in vars(args).items():
            if isinstance(value, list):
                setattr(args, name, [dashed.get(item, item) for item in value])
            elif isinstance(value, str):
                setattr(args, name, dashed.get(value, value))
        return args


def _hide_dashed(argv: Sequence[str]) -> tuple[list[str], dict[str, str]]:
    """``argv`` without its first ``--``, the arguments after it that start with ``-`` replaced by
    placeholders no option takes (they start with NUL, which no real argument holds); and the
    placeholders' arguments."""
    argv = list(argv)
    if "--" not in argv:
        return argv, {}
    cut = argv.index("--")
    dashed = {f"\0{i}": token for i, token in enumerate(argv[cut + 1 :]) if token.startswith("-")}
    hidden = {token: placeholder for placeholder, token in dashed.items()}
    return argv[:cut] + [hidden.get(token, token) for token in argv[cut + 1 :]], dashed


def option_strings(parser: argparse.ArgumentParser) -> list[str]:
    """A parser's long options (``--window``), in the order they were added."""
    return [name for action in parser._actions for name in action.option_strings if name.startswith("--")]


def did_you_mean(word: str, choices: Sequence[str]) -> str:
    """`` (did you mean X, Y or Z?)`` naming the nearest choices, or "" when none is near."""
    found = nearest(word, choices)
    if not found:
        return ""
    listed = found[0] if len(found) == 1 else f"{', '.join(found[:-1])} or {found[-1]}"
    return f" (did you mean {listed}?)"


def first_unknown_option(argv: Sequence[str], known: Collection[str]) -> str | None:
    """The first option of ``argv`` that is none of ``known`` nor a prefix of a known long option
    (argparse takes an unambiguous prefix), up to ``--``; numbers such as ``-1`` are values."""
    for token in argv:
        if token == "--":
            return None
        if not token.startswith("-") or token == "-" or _is_number(token):
            continue
        name = token.split("=", 1)[0] if token.startswith("--") else token[:2]
        if name in known or (name.startswith("--") and any(option.startswith(name) for option in known)):
            continue
        return name
    return None


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def leftover_text(extras: Sequence[str], options: Sequence[str]) -> str:
    """The message for arguments no option or positional took: the first unknown option with the
    nearest known ones, else the unexpected positional arguments."""
    unknown = [extra for extra in extras if extra.startswith("-") and extra != "-"]
    if unknown:
        name = unknown[0].split("=", 1)[0]
        return f"unknown option {name}{did_you_mean(name, options)}"
    return f"unexpected argument{'s' if len(extras) > 1 else ''}: {' '.join(extras)}"


def parse_command_line(parser: argparse.ArgumentParser, argv: Sequence[str]) -> argparse.Namespace:
    """Parse ``scenegrep [--version|-h] COMMAND ARGS...``: the top-level options by ``parser``, the
    command's arguments by its own parser (:meth:`CommandParser.parse_command`). ``command`` is
    None when no command is given. A command's parser is built only by ``parser`` (and added to
    its subparsers); argparse's own dispatch to it is not used, since it cannot intermix."""
    commands = _commands(parser)
    if not argv:
        return argparse.Namespace(command=None)
    name = argv[0]
    if name in ("-h", "--help", "--version"):
        return parser.parse_args([name])  # prints and exits
    if name.startswith("-"):
        parser.error(leftover_text([name], option_strings(parser)))
    if name not in commands:
        parser.error(f"unknown command {name!r}{did_you_mean(name, list(commands))}; commands: {', '.join(commands)}")
    args = commands[name].parse_command(argv[1:])
    args.command = name
    return args


def _commands(parser: argparse.ArgumentParser) -> dict[str, CommandParser]:
    """The parsers of the commands, by name."""
    (action,) = (a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)
