"""``scenegrep serve``: a local web page over a dataset: browse its traces, type a query, run
it with the dataset engine and open the matches in the same views as ``show`` and ``report``.

The server binds to 127.0.0.1 only and answers one request at a time in the main thread (a query
runs in the engine's worker processes while the page waits). Routes:

- ``GET /``: the page; ``GET /api/traces``: the catalog's traces; ``GET /api/runs``: past runs.
- ``POST /api/query`` with JSON ``{"kind", "text", "options"}``: runs the query; answers the
  run's id, status, counts and matches, or ``{"error": one line}`` with status 400.
- ``GET /view/TRACE_ID?run=RUN_ID``: the trace's view with the run's rows (``#match=N``).
- ``GET /report/RUN_ID``: the report of a run, its matches linked to ``/view/...``.
"""

from __future__ import annotations

import json
import math
import sys
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, HTTPServer
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, quote, unquote, urlsplit

from ..dataset import Dataset
from ..dataset.queries import QuerySpec
from ..dataset.results import RESULTS_FILE, Results
from ..dataset.run import RunOptions, run_query
from ..errors import UserError
from .data import build_view
from .page import asset, html_page, view_page
from .report import report_page
from .sources import ResultsSource, load_trace

HOST = "127.0.0.1"
MAX_BODY = 1 << 20
"""The largest query request accepted, in bytes."""


class DatasetServer(HTTPServer):
    """An HTTP server over the dataset at ``root``; queries run with ``jobs`` workers."""

    def __init__(self, root: Path, port: int = 0, jobs: int | None = None):
        self.dataset = Dataset(root)
        self.jobs = jobs
        super().__init__((HOST, port), Handler)

    @property
    def url(self) -> str:
        return f"http://{HOST}:{self.server_address[1]}/"


class Handler(BaseHTTPRequestHandler):
    """Routes requests (see the module docstring)."""

    server: DatasetServer

    def log_message(self, format: str, *args: Any) -> None:
        """Requests are not logged (the terminal shows only the address and errors)."""

    def do_GET(self) -> None:
        url = urlsplit(self.path)
        parts = [unquote(p) for p in url.path.strip("/").split("/")] if url.path.strip("/") else []
        query = parse_qs(url.query)
        try:
            if not parts:
                self._send(HTTPStatus.OK, _index_page(), "text/html")
            elif parts == ["api", "traces"]:
                self._json(HTTPStatus.OK, self.server.dataset.traces().to_pylist())
            elif parts == ["api", "runs"]:
                self._json(HTTPStatus.OK, _runs(self.server.dataset))
            elif len(parts) == 2 and parts[0] == "view":
                self._send(HTTPStatus.OK, self._view(parts[1], query.get("run", [""])[0]), "text/html")
            elif len(parts) == 2 and parts[0] == "report":
                self._send(HTTPStatus.OK, self._report(parts[1]), "text/html")
            else:
                self._json(HTTPStatus.NOT_FOUND, {"error": f"no page {url.path}"})
        except UserError as exc:
            self._json(HTTPStatus.BAD_REQUEST, {"error": exc.one_line()})

    def do_POST(self) -> None:
        if urlsplit(self.path).path != "/api/query":
            self._json(HTTPStatus.NOT_FOUND, {"error": f"no page {self.path}"})
            return
        try:
            length = int(self.headers.get("Content-Length", "0"))
            if length > MAX_BODY:
                raise UserError("the query request is too large")
            request = json.loads(self.rfile.read(length) or b"{}")
            self._json(HTTPStatus.OK, self._run(request))
        except UserError as exc:
            self._json(HTTPStatus.BAD_REQUEST, {"error": exc.one_line()})
        except (ValueError, TypeError, AttributeError) as exc:
            self._json(HTTPStatus.BAD_REQUEST, {"error": f"bad query request: {exc}"})

    # ------------------------------------------------------------------ pages
    def _run(self, request: dict[str, Any]) -> dict[str, Any]:
        if not isinstance(request, dict) or not {"kind", "text"} <= set(request):
            raise UserError("bad query request: it needs a 'kind' and a 'text'")
        options = {k: v for k, v in dict(request.get("options") or {}).items() if v not in (None, "")}
        spec = QuerySpec.of(str(request["kind"]), str(request["text"]), "<query>", **options)
        results = run_query(self.server.dataset.path, spec, RunOptions(jobs=self.server.jobs))
        matches = results.matches.to_pylist()
        for row in matches:
            row["href"] = f"/view/{quote(row['trace_id'])}?run={results.run_id}#match={row['match']}"
        return {
            "run_id": results.run_id,
            "status": results.status,
            "counts": results.counts(),
            "report": f"/report/{results.run_id}",
            "matches": matches,
        }

    def _results(self, run_id: str) -> Results:
        folder = self.server.dataset.path / "runs" / Path(run_id).name
        if not run_id or not (folder / RESULTS_FILE).is_file():
            raise UserError(f"the dataset has no run {run_id!r}")
        return Results.read(folder)

    def _view(self, trace_id: str, run_id: str) -> str:
        if not run_id:
            trace, road_map = load_trace(self.server.dataset.path, trace_id)
            return view_page(build_view(trace, road_map, trace_id=trace_id), back_link="/")
        source = ResultsSource.of_run(self.server.dataset.path, self._results(run_id))
        return view_page(source.view(trace_id), back_link="/")

    def _report(self, run_id: str) -> str:
        source = ResultsSource.of_run(self.server.dataset.path, self._results(run_id))
        return report_page(source, lambda trace_id, number: f"/view/{quote(trace_id)}?run={run_id}#match={number}")

    # ------------------------------------------------------------------ answers
    def _send(self, status: HTTPStatus, body: str, content_type: str) -> None:
        data = body.encode("utf-8")
        self.send_response(status)
        self.send_header("Content-Type", f"{content_type}; charset=utf-8")
        self.send_header("Content-Length", str(len(data)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        self.wfile.write(data)

    def _json(self, status: HTTPStatus, document: Any) -> None:
        self._send(status, json.dumps(_finite(document), default=str, allow_nan=False), "application/json")


def _finite(value: Any) -> Any:
    """The document with NaN and infinite numbers as nulls (JSON has none)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def _index_page() -> str:
    body = asset("serve.html").format(script=asset("serve.js"))
    return html_page("scenegrep serve", asset("report.css") + asset("serve.css"), body)


def _runs(dataset: Dataset) -> list[dict[str, Any]]:
    return dataset.sql(
        "SELECT run_id, kind, query, status, traces, pruned, matched, failed FROM runs ORDER BY started_at DESC"
    ).to_pylist()


def serve(root: Path, port: int, jobs: int | None) -> None:
    """Serve the dataset at ``root`` until interrupted (prints the address on stdout)."""
    with DatasetServer(root, port, jobs) as server:
        print(f"scenegrep: serving {root} at {server.url} (Ctrl-C stops)", flush=True)
        try:
            server.serve_forever()
        except KeyboardInterrupt:
            print("scenegrep: stopped", file=sys.stderr)
