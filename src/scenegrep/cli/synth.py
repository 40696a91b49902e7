"""``scenegrep synth PROGRAM.scenic --map MAP --runs N --steps T -o DIR``: simulated label traces.

Runs a Scenic program N times in Scenic's Newtonian driving simulator (see
:mod:`scenegrep.synth.simulate`; Scenic executes the program's Python code, so this is for
programs the user trusts), optionally adds perception-like noise
(:mod:`scenegrep.synth.noise`), and writes ``DIR/<program stem>-<run:03d>.parquet`` (scenegrep
Parquet traces) and ``DIR/manifest.json`` (:mod:`scenegrep.synth.folder`). Exit codes: 0
written, 2 error (a bad program is reported at its line:column; the manifest then lists the
traces written before the error).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any
from ..wording import counted


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
    from ..errors import UserError
    from ..progress import bar
    from ..synth.folder import MANIFEST, SynthFolder
    from ..synth.simulate import simulate_runs

    if min(args.runs, args.steps, args.max_iterations) < 1 or min(args.seed, args.noise_seed) < 0:
        raise UserError("--runs, --steps and --max-iterations must be at least 1, seeds non-negative")
    noise = _noise(args)
    folder = SynthFolder.open(args.output)
    traces = simulate_runs(
        args.program,
        map_path=args.map,
        runs=args.runs,
        steps=args.steps,
        seed=args.seed,
        max_iterations=args.max_iterations,
        noise=noise,
    )
    progress = bar(traces, args.quiet, total=args.runs, desc=Path(args.program).name, unit="run")
    written = folder.write(progress, args.program, args.map)
    if not args.quiet:
        print(f"scenegrep: wrote {counted(written, 'trace')} and {MANIFEST} to {folder.path}", file=sys.stderr)
    return 0
