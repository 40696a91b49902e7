"""``scenegrep serve``: a local web page over a dataset: browse its traces, type a query, run
it with the dataset engine and open the matches in the same views as ``show`` and ``report``.

The server binds to 127.0.0.1 only and answers each request in its own thread. Every request
passes the checks of :mod:`.guard` (its ``Host``; for the API the token the page holds; for
POSTs their ``Origin``, ``Content-Type`` and length); a request whose body does not arrive
within :data:`READ_TIMEOUT` seconds is dropped. A query runs in a child process with a time
limit (:mod:`.limited`), one at a time; it never compiles or runs a Scenic program with Scenic
itself, and file options name files inside the dataset only. Routes:

- ``GET /``: the page; ``GET /api/traces``: the catalog's traces; ``GET /api/runs``: past runs.
- ``POST /api/query`` with JSON ``{"kind", "text", "options"}``: runs the query; answers the
  run's id, status, counts and matches, or ``{"error": one line}`` with status 400 (408 past the
  time limit, 409 while another query runs).
- ``GET /view/TRACE_ID?run=RUN_ID``: the trace's view with the run's rows (``#match=N``).
- ``GET /report/RUN_ID``: the report of a run, its matches linked to ``/view/...``.
"""

from __future__ import annotations

import json
import math
import secrets
import sys
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, quote, unquote, urlsplit

from ..dataset import Dataset
from ..dataset.catalog import within
from ..dataset.queries import OPTIONS, QuerySpec
from ..dataset.results import RESULTS_FILE, Results
from ..dataset.traces import load_trace
from ..errors import UserError
from .data import build_view
from .guard import TIME_LIMIT, TOKEN_HEADER, Refused, check_host, check_post, check_token, dataset_file, public_message
from .limited import QueryTimeout, run_limited, start_fork_server, stop_all
from .page import asset, html_page, view_page
from .report import report_page
from .sources import ResultsSource

HOST = "127.0.0.1"
READ_TIMEOUT = 10.0
"""Seconds a connection may stay silent while its request is read."""
FILE_OPTIONS = ("vocabulary",)
"""Query options that name files (accepted only inside the dataset)."""


class DatasetServer(ThreadingHTTPServer):
    """An HTTP server over the dataset at ``root``; queries run with ``jobs`` workers for at
    most ``time_limit`` seconds. ``token`` is the random key of its page's API calls."""

    daemon_threads = True

    def __init__(self, root: Path, port: int = 0, jobs: int | None = None, time_limit: float = TIME_LIMIT):
        self.dataset = Dataset(root)
        self.jobs = jobs
        self.time_limit = time_limit
        self.token = secrets.token_urlsafe(32)
        self.query_lock = threading.Lock()
        super().__init__((HOST, port), Handler)
        start_fork_server()

    @property
    def address(self) -> str:
        """``127.0.0.1:PORT``, the only ``Host`` answered."""
        return f"{HOST}:{self.server_address[1]}"

    @property
    def url(self) -> str:
        return f"http://{self.address}/"


class Handler(BaseHTTPRequestHandler):
    """Routes requests (see the module docstring)."""

    server: DatasetServer
    timeout = READ_TIMEOUT

    def log_message(self, format: str, *args: Any) -> None:
        """Requests are not logged (the terminal shows only the address and errors)."""

    def do_GET(self) -> None:
        url = urlsplit(self.path)
        parts = [unquote(p) for p in url.path.strip("/").split("/")] if url.path.strip("/") else []
        query = parse_qs(url.query)
        try:
            check_host(self.headers, self.server.address)
            if parts[:1] == ["api"]:
                check_token(self.headers, self.server.token)
            if not parts:
                self._send(HTTPStatus.OK, _index_page(self.server.token), "text/html")
            elif parts == ["api", "traces"]:
                self._json(HTTPStatus.OK, self.server.dataset.traces().to_pylist())
            elif parts == ["api", "runs"]:
                self._json(HTTPStatus.OK, _runs(self.server.dataset))
            elif len(parts) == 2 and parts[0] == "view":
                self._send(HTTPStatus.OK, self._view(parts[1], query.get("run", [""])[0]), "text/html")
            elif len(parts) == 2 and parts[0] == "report":
                self._send(HTTPStatus.OK, self._report(parts[1]), "text/html")
            else:
                self._error(HTTPStatus.NOT_FOUND, f"no page {url.path}")
        except Refused as exc:
            self._error(exc.status, exc.reason)
        except UserError as exc:
            self._error(HTTPStatus.BAD_REQUEST, exc.one_line())

    def do_POST(self) -> None:
        try:
            check_host(self.headers, self.server.address)
            if urlsplit(self.path).path != "/api/query":
                raise Refused(HTTPStatus.NOT_FOUND, f"no page {self.path}")
            check_token(self.headers, self.server.token)
            request = self._body(check_post(self.headers, self.server.address))
            if not self.server.query_lock.acquire(blocking=False):
                raise Refused(HTTPStatus.CONFLICT, "another query is running; run this one when it ends")
            try:
                self._json(HTTPStatus.OK, self._run(request))
            finally:
                self.server.query_lock.release()
        except Refused as exc:
            self._error(exc.status, exc.reason)
        except QueryTimeout as exc:
            self._error(HTTPStatus.REQUEST_TIMEOUT, str(exc))
        except UserError as exc:
            self._error(HTTPStatus.BAD_REQUEST, exc.one_line())
        except TimeoutError:
            self.close_connection = True

    # ------------------------------------------------------------------ pages
    def _body(self, length: int) -> dict[str, Any]:
        """The request's JSON object (its body of ``length`` bytes, read within the timeout)."""
        data = self.rfile.read(length)
        if len(data) < length:
            raise Refused(HTTPStatus.BAD_REQUEST, "the request body is shorter than its Content-Length")
        try:
            request = json.loads(data or b"{}")
        except ValueError as exc:
            raise Refused(HTTPStatus.BAD_REQUEST, f"bad query request: {exc}") from None
        if not isinstance(request, dict) or not {"kind", "text"} <= set(request):
            raise Refused(HTTPStatus.BAD_REQUEST, "bad query request: it needs a 'kind' and a 'text'")
        return request

    def _run(self, request: dict[str, Any]) -> dict[str, Any]:
        options = request.get("options") or {}
        if not isinstance(options, dict):
            raise Refused(HTTPStatus.BAD_REQUEST, "bad query request: 'options' must be an object")
        options = {k: v for k, v in options.items() if v not in (None, "")}
        for name in FILE_OPTIONS:
            if name in options and name in OPTIONS.get(str(request["kind"]), {}):
                options[name] = dataset_file(self.server.dataset.path, options[name], name)
        spec = QuerySpec.of(str(request["kind"]), str(request["text"]), "<query>", **options)
        answer = run_limited(self.server.dataset.path, spec, self.server.jobs, self.server.time_limit)
        for row in answer["matches"]:
            if row.get("error"):
                row["error"] = public_message(row["error"], self.server.dataset.path)
        return answer

    def _results(self, run_id: str) -> Results:
        """The results of the run ``run_id``: a run the catalog records, whose folder is a plain
        name under ``runs/`` (no other file of the dataset, or outside it, is read for a name)."""
        dataset = self.server.dataset
        recorded = dataset.sql("SELECT count(*) AS n FROM runs WHERE run_id = ?", [run_id])["n"][0].as_py()
        folder = within(dataset.path / "runs", run_id) if Path(run_id).name == run_id else None
        if not recorded or folder is None or folder.parent != (dataset.path / "runs").resolve():
            raise UserError(f"the dataset has no run {run_id!r}")
        if not (folder / RESULTS_FILE).is_file():
            raise UserError(f"the run {run_id!r} has no results yet")
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
        self.send_header("X-Content-Type-Options", "nosniff")
        self.end_headers()
        self.wfile.write(data)

    def _json(self, status: HTTPStatus, document: Any) -> None:
        self._send(status, json.dumps(_finite(document), default=str, allow_nan=False), "application/json")

    def _error(self, status: HTTPStatus, message: str) -> None:
        """``{"error": message}`` with no absolute path in it."""
        self._json(status, {"error": public_message(message, self.server.dataset.path)})


def _finite(value: Any) -> Any:
    """The document with NaN and infinite numbers as nulls (JSON has none)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def _index_page(token: str) -> str:
    """The page, holding the server's API token (sent back in the ``X-Scenegrep-Token`` header)."""
    body = asset("serve.html").format(script=asset("serve.js"))
    attributes = {"data-token": token, "data-token-header": TOKEN_HEADER}
    return html_page("scenegrep serve", asset("report.css") + asset("serve.css"), body, attributes)


def _runs(dataset: Dataset) -> list[dict[str, Any]]:
    return dataset.sql(
        "SELECT run_id, kind, query, status, traces, pruned, matched, failed FROM runs ORDER BY started_at DESC"
    ).to_pylist()


def serve(root: Path, port: int, jobs: int | None, time_limit: float = TIME_LIMIT) -> None:
    """Serve the dataset at ``root`` until interrupted (prints the address on stdout)."""
    with DatasetServer(root, port, jobs, time_limit) as server:
        print(f"scenegrep: serving {root} at {server.url} (Ctrl-C stops)", flush=True)
        try:
            server.serve_forever()
        except KeyboardInterrupt:
            print("scenegrep: stopped", file=sys.stderr)
        finally:
            stop_all()
