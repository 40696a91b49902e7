"""Every command block of README.md runs as shown.

A command block is a ```` ```console ```` fence: each line starting with ``$ `` is a command (a
line ending in ``\\`` continues on the next), the lines up to the next command are output the
README shows. The commands run in README order, in a temporary copy of the repository (its
``git ls-files``, with ``../shared`` beside it) made once per test process, so a later example may
read what an earlier one wrote (``fleet``, ``r.parquet``). The commands are split into
:func:`groups` that share no file one of them writes, one test each, so ``pytest -n 2`` spreads
them over its workers. Each must exit 0, or the code its trailing comment names
(``# exit 1``); each output line shown must appear in the command's stdout or stderr, in order
within each stream, where ``...`` in a line stands for any text and a line ``...`` alone (or
``... (a remark)``) for any lines. ``scenegrep`` commands without pipes or redirections run in this process
(:func:`scenegrep.cli.main.main`, argv expanded by bash), the others in bash with ``scenegrep``
on the PATH. ``scenegrep serve``, which runs until Ctrl-C, is started on a free port (the shown
8765 read as that port), stopped with SIGINT once it printed its first line and answered a request
for its page, and must then exit 0.

:data:`EXCLUDED` lists the commands that do not run here, each with its reason.
"""

from __future__ import annotations

import io
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from contextlib import redirect_stderr, redirect_stdout
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from tests.conftest import REPO

README = REPO / "README.md"
EXCLUDED = {
    "python3 -m venv .venv && .venv/bin/pip install": "installs packages from the network into a new venv "
    "(tests/test_readme.py runs the first quick-start command's scenegrep part)",
}
"""Commands (by how they start) that this test does not run, and why."""


@dataclass
class Command:
    """A README command: its text, line in README.md, expected exit code and output lines."""

    text: str
    line: int
    code: int = 0
    output: list[str] = field(default_factory=list)


def commands(text: str) -> list[Command]:
    """Every command of the ```` ```console ```` blocks of ``text``, in order."""
    found: list[Command] = []
    lines = text.split("\n")
    inside, pending = False, ""
    for number, line in enumerate(lines, 1):
        if line.startswith("```"):
            inside = line == "```console"
            continue
        if not inside:
            continue
        if pending or line.startswith("$ "):
            body = (pending + " " + line.strip()) if pending else line[2:]
            if body.endswith("\\"):
                pending = body[:-1].rstrip()
                continue
            pending = ""
            code = re.search(r"#\s*exit (\d+)", body)
            found.append(Command(body, number, int(code.group(1)) if code else 0))
        elif found:
            found[-1].output.append(line)
    return found


def excluded(command: Command) -> str | None:
    """The reason ``command`` is not run here, or None."""
    return next((why for start, why in EXCLUDED.items() if command.text.startswith(start)), None)


def line_pattern(shown: str) -> re.Pattern[str]:
    """A shown output line as a pattern: ``...`` matches any text, the rest literally."""
    return re.compile(".*".join(re.escape(part) for part in shown.rstrip().split("...")) + r"\s*")


def missing_lines(shown: list[str], out: str, err: str) -> list[str]:
    """The shown lines not found in order in stdout or stderr (each stream in its own order)."""
    streams = [out.splitlines(), err.splitlines()]
    position = [0, 0]
    missing = []
    for line in shown:
        if line.strip() in ("", "...") or line.strip().startswith("... ("):
            continue
        pattern = line_pattern(line)
        for k, stream in enumerate(streams):
            hit = next((i for i in range(position[k], len(stream)) if pattern.fullmatch(stream[i])), None)
            if hit is not None:
                position[k] = hit + 1
                break
        else:
            missing.append(line)
    return missing


def test_the_readme_has_one_fence_for_commands():
    """Commands are in ```` ```console ```` fences only; other fences hold no ``$`` lines."""
    text = README.read_text()
    for block in re.findall(r"^```(\w*)\n(.*?)^```", text, re.S | re.M):
        kind, body = block
        if kind != "console":
            assert not re.search(r"^\$ ", body, re.M), body[:200]
    found = commands(text)
    assert len(found) > 50
    for start in EXCLUDED:  # no stale exclusion
        assert any(command.text.startswith(start) for command in found), start


WRITES = ("-o", "--output", "--into", "--refav", "--openscenario", "--scenic", "--mcap", ">")
"""The options (and the shell redirection) whose next word is a file or folder a command writes."""


def _words(command: Command) -> list[str]:
    return [word.strip("'\"") for word in command.text.split()]


def _top(word: str) -> str:
    """A path's first component (``fleet`` of ``fleet/runs/x``), which names what a command reads or writes."""
    return word.split("/", 1)[0]


def written(command: Command) -> set[str]:
    """The first components of the paths ``command`` writes: the words after :data:`WRITES` in its
    ``scenegrep`` part (``grep -o`` is not an output) or after a redirection."""
    words = _words(command)
    start = words.index("scenegrep") if "scenegrep" in words else len(words)
    return {
        _top(after)
        for k, (before, after) in enumerate(zip(words, words[1:]))
        if before == ">" or (k >= start and before in WRITES)
    }


def groups(found: list[Command]) -> list[list[Command]]:
    """``found`` in groups, each in README order: a command joins every earlier group that writes a
    path whose first component it names, or names a path it writes, so no group reads or overwrites
    what another writes. The groups come largest first (the long tests start first)."""
    members: list[list[Command]] = []
    writes: list[set[str]] = []
    names: list[set[str]] = []
    for command in found:
        group, wrote, named = [command], written(command), {_top(word) for word in _words(command)}
        joined = [k for k in range(len(members)) if writes[k] & named or names[k] & wrote]
        for k in reversed(joined):
            group = members.pop(k) + group
            wrote |= writes.pop(k)
            named |= names.pop(k)
        members.append(group)
        writes.append(wrote)
        names.append(named)
    members = [sorted(group, key=lambda c: c.line) for group in members]
    return sorted(members, key=lambda group: (-len(group), group[0].line))


GROUPS = groups([command for command in commands(README.read_text()) if not excluded(command)])


@pytest.fixture(scope="session")
def workspace(tmp_path_factory) -> Path:
    """A copy of the repository's tracked files, with ../shared beside it (once per test process:
    the groups of commands write different files)."""
    root = tmp_path_factory.mktemp("readme")
    files = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True, check=True).stdout
    copy = root / "repo"
    for name in files.decode().split("\0"):
        if name and (REPO / name).is_file():
            (copy / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(REPO / name, copy / name)
    shared = REPO.parent / "shared"
    if shared.is_dir():
        (root / "shared").symlink_to(shared.resolve())
    return copy


def shell_env(workspace: Path) -> dict[str, str]:
    """The environment of commands run in bash: ``scenegrep`` on the PATH runs this checkout."""
    import scenegrep

    bin_dir = workspace.parent / "bin"
    bin_dir.mkdir(exist_ok=True)
    shim = bin_dir / "scenegrep"
    shim.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m scenegrep "$@"\n')
    shim.chmod(0o755)
    source = str(Path(scenegrep.__file__).resolve().parents[1])
    path = f"{bin_dir}:{Path(sys.executable).parent}:{os.environ['PATH']}"  # the venv's tools (scenic)
    return {**os.environ, "PATH": path, "PYTHONPATH": source}


def in_process(text: str) -> bool:
    """Whether a command is one scenegrep call (no pipe, redirection or sequence)."""
    return text.startswith("scenegrep ") and not re.search(r"[|<>;&`]|\$\(", re.sub(r"'[^']*'|\"[^\"]*\"", "", text))


def argv_of(text: str, cwd: Path) -> list[str]:
    """The arguments bash would pass to a command (quotes removed, globs expanded)."""
    words = subprocess.run(
        ["bash", "-c", f"printf '%s\\0' {text.split(' ', 1)[1]}"], cwd=cwd, capture_output=True, check=True
    )
    return words.stdout.decode().split("\0")[:-1]


def serve_briefly(command: Command, cwd: Path, env: dict[str, str]) -> tuple[int, str, str]:
    """Run a ``scenegrep serve`` command on a free port until it prints its first line, then stop
    it with SIGINT: its exit code, stdout and stderr; the command's shown output names that port."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    command.output = [line.replace(":8765", f":{port}") for line in command.output]
    server = subprocess.Popen(
        ["bash", "-c", f"exec {command.text} --port {port}"],
        cwd=cwd,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    watchdog = threading.Timer(120, server.kill)  # a server that never prints is killed (exit -9)
    watchdog.start()
    try:
        first = server.stdout.readline()  # type: ignore[union-attr]
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=60) as page:  # it serves: stop it now
            assert page.status == 200
    finally:
        watchdog.cancel()
        server.send_signal(signal.SIGINT)
        rest = server.communicate(timeout=60)[0]
    return server.returncode, first + rest, ""


def run(command: Command, cwd: Path, env: dict[str, str]) -> tuple[int, str, str]:
    """Run one command: its exit code, stdout and stderr."""
    if command.text.startswith("scenegrep serve "):
        return serve_briefly(command, cwd, env)
    if in_process(command.text):
        from scenegrep.cli.main import main

        out, err = io.StringIO(), io.StringIO()
        previous = os.getcwd()
        os.chdir(cwd)
        try:
            with redirect_stdout(out), redirect_stderr(err):
                code = main(argv_of(command.text, cwd))
        finally:
            os.chdir(previous)
        return code, out.getvalue(), err.getvalue()
    done = subprocess.run(["bash", "-c", command.text], cwd=cwd, env=env, capture_output=True, text=True, timeout=600)
    return done.returncode, done.stdout, done.stderr


def test_groups_share_no_written_path():
    """Every command runs in one group; a path one group writes is named by no other group."""
    assert sorted(c.line for group in GROUPS for c in group) == [
        c.line for c in commands(README.read_text()) if not excluded(c)
    ]
    assert len(GROUPS) > 5
    for k, group in enumerate(GROUPS):
        wrote = set().union(*map(written, group))
        for other in GROUPS[:k] + GROUPS[k + 1 :]:
            assert not wrote & {_top(word) for c in other for word in _words(c)}, (group[0].line, other[0].line)


def test_a_command_joins_the_group_that_reads_what_it_writes():
    """A later writer of what an earlier command read runs after it, in its group (else a group
    run first could change what the other reads)."""
    found = [Command("scenegrep info a.parquet", 1), Command("scenegrep info b.parquet", 2)]
    found.append(Command("scenegrep spre x b.parquet -o a.parquet", 3))
    assert [[c.line for c in group] for group in groups(found)] == [[1, 3], [2]]


@pytest.mark.slow
@pytest.mark.real_data
@pytest.mark.parametrize("group", GROUPS, ids=lambda group: f"README.md:{group[0].line}+{len(group) - 1}")
def test_every_readme_command_runs_as_shown(group, workspace, real_data):
    """The commands of one group, in README order (see the module docstring)."""
    env = shell_env(workspace)
    failures = []
    ran = 0
    for command in group:
        start = time.monotonic()
        code, out, err = run(command, workspace, env)
        print(f"{time.monotonic() - start:6.1f} s  exit {code}  README.md:{command.line}: {command.text[:100]}")
        ran += 1
        missing = missing_lines(command.output, out, err)
        if code != command.code or missing:
            failures.append(
                f"README.md:{command.line}: $ {command.text}\n  exit {code} (expected {command.code})"
                + "".join(f"\n  missing: {line}" for line in missing)
                + f"\n  stdout: {out[-1500:]}\n  stderr: {err[-1500:]}"
            )
    assert not failures, f"{len(failures)} of {ran} commands:\n" + "\n".join(failures)
