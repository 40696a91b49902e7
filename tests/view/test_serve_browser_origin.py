"""In headless Chromium: a page on another origin cannot use ``scenegrep serve`` (neither read
its API nor make it run a query), a foreign host name gets nothing, and the server's own page
still works."""

from __future__ import annotations

import functools
import http.server
import json
import threading

import pytest

from tests.view.conftest import fetch, screenshot
from tests.view.test_browser import wait_for

pytestmark = [pytest.mark.slow, pytest.mark.browser, pytest.mark.real_data]

HOSTILE = """<!doctype html><title>elsewhere</title><script>
window.outcomes = {{}};
const target = "{target}";
const body = JSON.stringify({{kind: "spre", text: "{text}", options: {{}}}});
async function attempt(name, request) {{
  try {{
    const response = await request;
    window.outcomes[name] = response.type === "opaque" ? "opaque" : response.status;
  }} catch (error) {{
    window.outcomes[name] = "blocked";
  }}
}}
Promise.all([
  attempt("json-post", fetch(target + "api/query",
    {{method: "POST", headers: {{"Content-Type": "application/json", "X-Scenegrep-Token": "guess"}}, body}})),
  attempt("simple-post", fetch(target + "api/query",
    {{method: "POST", mode: "no-cors", headers: {{"Content-Type": "text/plain"}}, body}})),
  attempt("traces", fetch(target + "api/traces")),
  attempt("page", fetch(target)),
]).then(() => {{ window.done = true; }});
</script>"""
TEXT = "[[:construction_vehicle:]]+ [[:bicycle:]]"
"""A query no other test runs (whether it ran shows in the runs table)."""


@pytest.fixture
def elsewhere(tmp_path, server):
    """A page on another origin (another port of 127.0.0.1) that tries the server's API."""
    (tmp_path / "index.html").write_text(HOSTILE.format(target=server.url, text=TEXT))
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(tmp_path))
    with http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler) as other:
        threading.Thread(target=other.serve_forever, daemon=True).start()
        yield f"http://127.0.0.1:{other.server_address[1]}/index.html"
        other.shutdown()


def test_a_page_on_another_origin_cannot_use_the_server(browser, server, elsewhere):
    browser.get(elsewhere)
    wait_for(browser, "window.done === true", timeout=30)
    outcomes = browser.execute_script("return window.outcomes")
    assert outcomes == {"json-post": "blocked", "simple-post": "opaque", "traces": "blocked", "page": "blocked"}
    runs = json.loads(fetch(server, "api/runs")[1])
    assert TEXT not in [run["query"] for run in runs]  # the request that got through was refused


def test_a_foreign_host_name_gets_nothing_and_the_own_page_works(browser, server):
    browser.get(f"http://localhost:{server.server_address[1]}/")
    assert "this server answers only requests for" in browser.find_element("tag name", "body").text
    browser.get(server.url)
    wait_for(browser, "document.querySelectorAll('#traces tbody tr').length > 0")
    assert len(browser.find_elements("css selector", "#traces tbody tr")) == 62
    screenshot(browser, "serve-own-page")
