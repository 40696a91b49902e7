"""What the query commands share: one run over DATA files or over an ``--dataset``, through the
dataset engine either way (:func:`scenegrep.dataset.files.query_files`,
:func:`scenegrep.dataset.run.run_query`), and one output of its results table.

Output: one line per match ``SOURCE#NAME:START-END  correspondence``
(:mod:`scenegrep.dataset.places`: the source path as given, dataset frame indices of the
window's first and last frame, inclusive), or every row of the results table with ``--json``
(one object per row) or ``--csv``; a failed trace's error and a summary on stderr. Over files,
each trace's rows are printed as soon as it is done. ``--output FILE`` also writes the table as
Parquet, which ``show``, ``report`` and ``export`` read. Exit codes: 0 some trace matches, 1 none,
2 user error (one input, a file or recording rather than a folder, whose only trace fails is one,
as in ``label`` and ``info``), 3 some path or trace failed (the others are done), 130 interrupted
(a dataset run keeps the results so far; ``--resume`` continues).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from .inputs import is_one_input
from ..wording import counted, verb
from .exit_codes import EXIT_INTERRUPTED, EXIT_NO_MATCH, EXIT_SOME_FAILED
from .options import reject_dataset_only, report_unknown_layers, run_options_of


def run_query_command(
    args: argparse.Namespace, kind: str, query: str, origin: str, options: dict[str, Any], paths: list[str]
) -> int:
    """Run a query over ``paths`` or ``args.dataset``, print its results; returns the exit code."""
    from .. import readers
    from ..dataset import QuerySpec
    from ..dataset.places import as_given
    from ..dataset.queries import uses_map
    from ..model.layers import UnknownLayers

    spec = QuerySpec.of(kind, query, origin, **options)
    if getattr(args, "map", None):
        readers.read_map(args.map)  # a bad --map is the user's error, before any trace is read
    printer = RowPrinter(args, shown=None if args.dataset else as_given(paths))
    results, where = results_of(args, spec, paths, printer)
    if args.output:
        results.write_parquet(args.output)
    counts = results.counts()
    if not args.quiet:
        if not args.dataset:  # a dataset run said so before querying (_report_plan)
            _report_pruned(reason for reason in results.with_status("pruned")["explanation"].to_pylist())
        _summary(results, where or (f"; results in {args.output}" if args.output else ""))
    print_warnings(results.warnings, args)
    if uses_map(spec):
        report_unknown_layers(UnknownLayers(spec.option("unknown_layers"), Counter(results.assumed)))
        if not counts["matched"]:
            _nearest_misses(spec, results, args)
    if results.status == "interrupted":
        return EXIT_INTERRUPTED
    if counts["failed"]:
        return EXIT_SOME_FAILED
    return 0 if counts["matched"] else EXIT_NO_MATCH


def print_warnings(warnings: Iterable[str], args: argparse.Namespace) -> None:
    """Each warning on stderr (``scenegrep: warning: ...``), unless ``-q``."""
    for warning in [] if args.quiet else warnings:
        print(f"scenegrep: warning: {warning}", file=sys.stderr)


def results_of(
    args: argparse.Namespace, spec: Any, paths: list[str], printer: Callable[[list[dict[str, Any]]], None]
) -> tuple[Any, str]:
    """The results of ``spec`` over ``paths`` or over ``args.dataset`` (one engine either way), each
    trace's rows shown to ``printer``, and where a dataset run keeps them ("" over files)."""
    if args.dataset:
        return _over_dataset(args, spec, paths, printer)
    return _over_files(args, spec, paths, printer), ""


def _over_files(args: argparse.Namespace, spec: Any, paths: list[str], printer: RowPrinter) -> Any:
    from ..dataset.files import query_files
    from ..errors import UserError

    reject_dataset_only(args)
    if not paths:
        raise UserError("give DATA (trace files or directories) or --dataset")
    if len(paths) > 1 or not is_one_input(paths[0]):
        return query_files(paths, spec, getattr(args, "map", None), printer)
    alone = LoneFailure(printer)
    results = query_files(paths, spec, getattr(args, "map", None), alone)
    alone.raise_if_alone()
    return results


class LoneFailure:
    """The rows callback of a query over one input: it holds back the first trace's rows while
    they are a failure, until another trace shows the input held several (then it passes them on);
    :meth:`raise_if_alone` makes a failure of the input's only trace the command's error."""

    def __init__(self, printer: Callable[[list[dict[str, Any]]], None]):
        self.printer = printer
        self.held: list[dict[str, Any]] | None = None
        self.seen = False

    def __call__(self, rows: list[dict[str, Any]]) -> None:
        """Pass one trace's rows on, or hold them (see the class docstring)."""
        first, self.seen = not self.seen, True
        if first and rows and all(row["status"] == "failed" for row in rows):
            self.held = rows
            return
        if self.held is not None:
            self.printer(self.held)
            self.held = None
        self.printer(rows)

    def raise_if_alone(self) -> None:
        """Raise the held failure (the input's only trace failed) as a user error."""
        from ..errors import UserError

        if self.held is not None:
            raise UserError(self.held[0]["error"])


def _over_dataset(args: argparse.Namespace, spec: Any, paths: list[str], printer: RowPrinter) -> tuple[Any, str]:
    from ..dataset.run import run_query
    from ..errors import UserError

    if paths:
        raise UserError("give either DATA paths or --dataset, not both")
    on_plan = None if args.quiet else _report_plan
    results = run_query(Path(args.dataset).resolve(), spec, run_options_of(args), on_plan=on_plan)
    printer(results.table.to_pylist())
    state = " (interrupted: continue with --resume)" if results.status == "interrupted" else ""
    where = (
        f"{state}; results in {Path(args.dataset) / 'runs' / results.run_id / 'results.parquet'} "
        f"and the catalog (SELECT * FROM results WHERE run_id = '{results.run_id}')"
    )
    return results, where


class RowPrinter:
    """Prints result rows as the options ask: text lines for matches (and, with ``--explain``,
    the explanation of traces without one), or every row as JSON or CSV; failed rows' errors on
    stderr; nothing with ``-q``. ``--max-count N`` prints at most N matches per trace. With
    ``failures_only`` it prints only the failed rows' errors. ``shown`` turns a row's recorded
    source into the one its text lines print (default: as recorded)."""

    def __init__(
        self, args: argparse.Namespace, failures_only: bool = False, shown: Callable[[str], str] | None = None
    ):
        from ..dataset.results import csv_writer

        self.args = args
        self.shown = shown
        self.failures_only = failures_only
        self.limit = getattr(args, "max_count", None)
        self.explain = getattr(args, "explain", False)
        wants_csv = getattr(args, "csv", False) and not failures_only
        self.write_csv = csv_writer(sys.stdout) if wants_csv and not args.quiet else None

    def __call__(self, rows: list[dict[str, Any]]) -> None:
        """Print one trace's rows (or a whole table's)."""
        if self.args.quiet:
            return
        from ..dataset.results import json_line

        for row in rows:
            if row["status"] == "failed":
                print(f"scenegrep: failed: {row['name']}: {row['error']}", file=sys.stderr)
            if self.failures_only:
                continue
            if self.limit is not None and row["match"] >= self.limit:
                continue
            if self.write_csv is not None:
                self.write_csv(row)
            elif self.args.json:
                sys.stdout.write(json_line(row) + "\n")
            else:
                sys.stdout.write("".join(line + "\n" for line in self._lines(row)))
        sys.stdout.flush()

    def _lines(self, row: dict[str, Any]) -> list[str]:
        explanation = (row["explanation"] or "").splitlines() if self.explain else []
        if row["status"] == "no match" and explanation:
            return [f"{self._place(row)}  no match: {explanation[0]}", *(f"    {line}" for line in explanation[1:])]
        if row["status"] != "match":
            return []
        return [match_line(row, self._place(row)), *(f"    {line}" for line in explanation)]

    def _place(self, row: dict[str, Any]) -> str:
        """``SOURCE#NAME:START-END`` (:func:`scenegrep.dataset.places.place`), or
        ``SOURCE#NAME`` for a row without frames."""
        from ..dataset.places import place

        source = row["source"] or ""
        return place(
            self.shown(source) if self.shown else source, row["name"], row.get("start_frame"), row.get("end_frame")
        )


def match_line(row: dict[str, Any], where: str) -> str:
    """``WHERE  object=id ...  |  variable=value ...  [holds] require ...`` for a match row
    printed at ``where`` (its ``SOURCE#NAME:START-END``)."""
    pairs = "  ".join(f"{k}={v}" for k, v in json.loads(row["correspondence"] or "{}").items())
    text = f"{where}  {pairs}".rstrip()
    values = json.loads(row.get("values") or "{}")
    variables = {k: v for k, v in values.items() if not isinstance(v, bool)}
    if variables:
        text += "  |  " + "  ".join(f"{name}={_value_text(v)}" for name, v in variables.items())
    soft = {k: v for k, v in values.items() if isinstance(v, bool)}
    if soft:
        text += "  |  " + "  ".join(f"[{'holds' if ok else 'fails'}] {name}" for name, ok in soft.items())
    return text


def _value_text(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, list):
        return "(" + ", ".join("?" if c is None else f"{c:.6g}" for c in value) + ")"
    return "?" if value is None else str(value)


def _nearest_misses(spec: Any, results: Any, args: argparse.Namespace) -> None:
    """Print the nearest misses of a Scenic query that matched nothing (:mod:`scenegrep.dataset.misses`)."""
    from ..dataset.misses import misses_of_results
    from .misses import print_misses, what_of

    misses = misses_of_results(spec, results, args.dataset, getattr(args, "map", None))
    print_misses(misses, what_of(spec.kind), args.json)


def _report_plan(plan: Any) -> None:
    total = len(plan.kept) + len(plan.pruned)
    print(f"scenegrep: querying {len(plan.kept)} of {counted(total, 'trace')}", file=sys.stderr)
    _report_pruned(reason for _, reason in plan.pruned)


def _report_pruned(reasons: Iterable[str]) -> None:
    """One line per pruning reason: how many traces the planner pruned for it."""
    for reason, count in Counter(_general(r) for r in reasons).most_common():
        print(f"scenegrep: pruned {count}: {reason}", file=sys.stderr)


def _general(reason: str) -> str:
    """A pruning reason without the trace's own numbers (so reasons group)."""
    return reason.split(" (at most")[0]


def _summary(results: Any, where: str) -> None:
    counts = results.counts()
    print(
        f"scenegrep: {counts['matched']} of {counted(counts['traces'], 'trace')} {verb(counts['matched'], 'match')}, "
        f"{counts['pruned']} pruned, "
        f"{counts['failed']} failed{where}",
        file=sys.stderr,
    )
