"""``scenegrep synth PROGRAM.scenic --map MAP --runs N --steps T -o DIR``: simulated label traces.

Runs a Scenic program N times in Scenic's Newtonian driving simulator (see
:mod:`scenegrep.synth.simulate`; Scenic executes the program's Python code, so this is for
programs the user trusts), optionally adds perception-like noise
(:mod:`scenegrep.synth.noise`), and writes ``DIR/<program stem>-<run:03d>.parquet`` (scenegrep
Parquet traces, each written atomically, replacing a file of the same name) and
``DIR/manifest.json``. Each trace's map path is stored relative to DIR, so the directory and
the map can move together. The manifest lists every trace ``synth`` wrote into DIR (entries of
other programs written there before are kept; those of rewritten files are replaced), with
paths relative to DIR. Exit codes: 0 written, 2 error (a bad program is reported at its
line:column; the manifest then lists the traces written before the error).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any

MANIFEST = "manifest.json"
MANIFEST_FORMAT = "scenegrep-synth-manifest"


def add_parser(subparsers: Any) -> None:
    parser = subparsers.add_parser(
        "synth",
        help="simulate a Scenic program into labeled traces (runs the program's Python: trusted programs only)",
        description="Run a Scenic program (model scenic.simulators.newtonian.driving_model) N times in Scenic's "
        "Newtonian driving simulator and write one scenegrep Parquet trace per run, with positions, headings, "
        "velocities, lanes and the primitive behaviour running at each 0.1 s step, plus DIR/manifest.json. "
        "Warning: Scenic runs the program's Python code with your rights (that is Scenic's nature); synth only "
        "programs you trust. The map must be an OpenDRIVE .xodr file; Scenic reads a copy of it in scenegrep's "
        "cache and never a .snet file beside it.",
    )
    parser.add_argument("program", metavar="PROGRAM", help="a .scenic file using the Newtonian driving model")
    parser.add_argument("--map", required=True, metavar="MAP", help="OpenDRIVE road map (.xodr)")
    parser.add_argument("--runs", type=int, required=True, metavar="N", help="number of simulations")
    parser.add_argument("--steps", type=int, required=True, metavar="T", help="time steps per simulation (0.1 s)")
    parser.add_argument("-o", "--output", required=True, metavar="DIR", help="output directory")
    parser.add_argument("--seed", type=int, default=0, metavar="S", help="base seed (default 0)")
    parser.add_argument(
        "--max-iterations", type=int, default=50, metavar="K", help="simulations tried per run before giving up"
    )
    noise = parser.add_argument_group("noise")
    noise.add_argument("--noise-position", type=float, default=0.0, metavar="M", help="position jitter s.d. (m)")
    noise.add_argument("--noise-heading", type=float, default=0.0, metavar="RAD", help="heading jitter s.d. (rad)")
    noise.add_argument("--drop-frames", type=float, default=0.0, metavar="P", help="probability of dropping a frame")
    noise.add_argument(
        "--confuse-behaviours", type=float, default=0.0, metavar="Q", help="probability of confusing a behaviour label"
    )
    noise.add_argument(
        "--confusion",
        choices=("replace", "augment"),
        default="replace",
        help="a confused label replaces the true one, or joins it in the label set",
    )
    noise.add_argument("--noise-seed", type=int, default=0, metavar="S", help="seed of the noise (default 0)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bar or summary")
    parser.set_defaults(run=run)


def _noise(args: argparse.Namespace) -> Any:
    """The requested noise, or None when every amount is zero."""
    from ..errors import UserError
    from ..synth.noise import LabelNoise

    amounts = (args.noise_position, args.noise_heading, args.drop_frames, args.confuse_behaviours)
    if not any(amounts):
        return None
    try:
        return LabelNoise(*amounts, confusion=args.confusion, seed=args.noise_seed)
    except ValueError as exc:
        raise UserError(str(exc)) from None


def run(args: argparse.Namespace) -> int:
    from ..errors import UserError, at
    from ..model import MapSource
    from ..progress import bar
    from ..synth.simulate import simulate_runs
    from ..writers import write_trace_parquet

    if min(args.runs, args.steps, args.max_iterations) < 1 or min(args.seed, args.noise_seed) < 0:
        raise UserError("--runs, --steps and --max-iterations must be at least 1, seeds non-negative")
    noise = _noise(args)
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise UserError("not a directory", at(out))
    previous = _read_manifest(out / MANIFEST)
    traces = simulate_runs(
        args.program,
        map_path=args.map,
        runs=args.runs,
        steps=args.steps,
        seed=args.seed,
        max_iterations=args.max_iterations,
        noise=noise,
    )
    stored_map = MapSource(os.path.relpath(args.map), "opendrive")
    stored_program = _relative(args.program, out)
    entries: list[dict[str, Any]] = []
    try:
        for trace in bar(traces, args.quiet, total=args.runs, desc=Path(args.program).name, unit="run"):
            path = write_trace_parquet(replace(trace, map_source=stored_map), out / f"{trace.name}.parquet")
            entries.append(_entry(path.name, trace, stored_program, _relative(args.map, out)))
    finally:  # the manifest lists what was written, even when a later run fails
        if entries:
            _write_manifest(out / MANIFEST, previous, entries)
    if not args.quiet:
        print(f"scenegrep: wrote {len(entries)} traces and {MANIFEST} to {out}", file=sys.stderr)
    return 0


def _relative(path: str, out: Path) -> str:
    """A path as seen from the output directory."""
    return os.path.relpath(Path(path).absolute(), out.absolute())


def _entry(file: str, trace: Any, program: str, map_path: str) -> dict[str, Any]:
    """The manifest entry of one written trace (``program`` and ``map_path`` relative to DIR)."""
    a = trace.attributes
    return {
        "file": file,
        "program": program,
        "map": map_path,
        "seed": a["seed"],
        "run": a["run"],
        "run_seed": a["run_seed"],
        "steps": a["steps"],
        "frames": trace.n_frames,
        "objects": dict(zip(trace.objects.id.tolist(), trace.objects.category.tolist())),
        "rejected_simulations": a["rejected_simulations"],
        "noise": a.get("noise"),
    }


def _read_manifest(path: Path) -> list[dict[str, Any]]:
    """The entries of an existing manifest (none when there is no file)."""
    from ..errors import UserError, at

    if not path.exists():
        return []
    try:
        doc = json.loads(path.read_text())
        if doc.get("format") != MANIFEST_FORMAT:
            raise ValueError
        return list(doc["traces"])
    except (OSError, ValueError, AttributeError, KeyError, TypeError):
        raise UserError("not a scenegrep synth manifest; move it away or choose another -o DIR", at(path)) from None


def _write_manifest(path: Path, previous: list[dict[str, Any]], entries: list[dict[str, Any]]) -> None:
    """Write the manifest atomically: the previous entries of other files, then the new ones, by file name."""
    from ..writers.atomic import atomic_path

    written = {e["file"] for e in entries}
    traces = sorted([e for e in previous if e.get("file") not in written] + entries, key=lambda e: e["file"])
    doc = {"format": MANIFEST_FORMAT, "paths": "relative to this file's directory", "traces": traces}
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(doc, indent=1) + "\n")
