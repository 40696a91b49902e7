"""``scenegrep serve`` answers only its own page: Host, Origin, Content-Type, token, file options,
error messages, body lengths, half-sent requests and the time limit of a query."""

from __future__ import annotations

import contextlib
import http.client
import json
import os
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request
from email.message import Message
from http import HTTPStatus
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.dataset.queries import QuerySpec
from scenegrep.view import guard, limited
from scenegrep.view.guard import Refused
from scenegrep.view.serve import Handler
from tests.conftest import REPO
from tests.view.conftest import fetch

ADDRESS = "127.0.0.1:8765"
SPRE = {"kind": "spre", "text": "[[:pedestrian:]]+", "options": {}}
SCENE_PROGRAM = (REPO / "examples" / "scenes" / "fig3_car_ahead.scenic").read_text()
SLOW = {
    "kind": "scenario",
    "text": (REPO / "examples" / "queries" / "s1_lane_change_stationary_car.scenic").read_text(),
    "options": {"window": "75", "all": True, "explain": True},
}
HEAVY = {
    "kind": "spre",
    "text": "[E(x := [:car:]) (E(y := [:car:]) (E(z := [:car:]) (@dist(x, y) > @dist(y, z))))]",
    "options": {},
}
"""A query that takes tens of seconds over the real dataset on any machine (every triple of cars
in every frame: about 70 s on one core here), for the time-limit tests."""


def headers(**fields: str) -> Message:
    message = Message()
    for name, value in fields.items():
        message[name.replace("_", "-")] = value
    return message


def refused(check, *args) -> HTTPStatus:
    with pytest.raises(Refused) as caught:
        check(*args)
    return caught.value.status


# ---------------------------------------------------------------------------- the checks


def test_host_must_be_the_bound_address_and_port():
    guard.check_host(headers(Host=ADDRESS), ADDRESS)
    for host in ("localhost:8765", "127.0.0.1:8766", "127.0.0.1", "evil.example:8765", ""):
        assert refused(guard.check_host, headers(Host=host), ADDRESS) == HTTPStatus.FORBIDDEN, host
    assert refused(guard.check_host, headers(), ADDRESS) == HTTPStatus.FORBIDDEN


def test_the_token_must_be_the_servers_own():
    guard.check_token(headers(X_Scenegrep_Token="abc"), "abc")
    for sent in (headers(), headers(X_Scenegrep_Token="abd"), headers(X_Scenegrep_Token="")):
        assert refused(guard.check_token, sent, "abc") == HTTPStatus.FORBIDDEN


def test_a_post_needs_its_own_origin_json_and_a_bounded_length():
    good = {"Content_Type": "application/json; charset=utf-8", "Content_Length": "12"}
    assert guard.check_post(headers(**good), ADDRESS) == 12
    assert guard.check_post(headers(**good, Origin=f"http://{ADDRESS}"), ADDRESS) == 12
    cases = [
        ({**good, "Origin": "http://evil.example"}, HTTPStatus.FORBIDDEN),
        ({**good, "Origin": "null"}, HTTPStatus.FORBIDDEN),
        ({**good, "Origin": "http://localhost:8765"}, HTTPStatus.FORBIDDEN),
        ({**good, "Content_Type": "text/plain"}, HTTPStatus.UNSUPPORTED_MEDIA_TYPE),
        ({"Content_Length": "12"}, HTTPStatus.UNSUPPORTED_MEDIA_TYPE),
        ({**good, "Content_Length": "-1"}, HTTPStatus.BAD_REQUEST),
        ({**good, "Content_Length": "1e3"}, HTTPStatus.BAD_REQUEST),
        ({**good, "Content_Length": str(guard.MAX_BODY + 1)}, HTTPStatus.REQUEST_ENTITY_TOO_LARGE),
        ({"Content_Type": "application/json"}, HTTPStatus.LENGTH_REQUIRED),
    ]
    for fields, status in cases:
        assert refused(guard.check_post, headers(**fields), ADDRESS) == status, fields


def test_file_options_name_regular_files_inside_the_dataset_only(tmp_path):
    root = tmp_path / "fleet"
    (root / "vocab").mkdir(parents=True)
    (root / "vocab" / "mine.json").write_text("{}")
    (tmp_path / "outside.json").write_text("{}")
    (root / "link.json").symlink_to(tmp_path / "outside.json")
    assert guard.dataset_file(root, "vocab/mine.json", "vocabulary") == "vocab/mine.json"
    for value in (str(tmp_path / "outside.json"), "../outside.json", "link.json", "vocab", "absent.json", 3):
        assert refused(guard.dataset_file, root, value, "vocabulary") == HTTPStatus.BAD_REQUEST, value


@given(
    st.lists(st.from_regex(r"[A-Za-z0-9_.-]{1,8}", fullmatch=True).filter(lambda p: p not in (".", "..")), max_size=4)
)
def test_messages_for_the_page_hold_no_absolute_path(parts):
    root = Path("/home/someone/fleet")
    inside = "/".join(["traces", *parts, "t.parquet"])
    text = (
        f"{root}/{inside}: bad; {root}: no trace; /usr/lib/python3/x/{''.join(p + '/' for p in parts)}scenic.py:3: oops"
    )
    public = guard.public_message(text, root)
    assert public == f"{inside}: bad; DATASET: no trace; scenic.py:3: oops"
    assert "/home" not in public and "/usr" not in public


# ---------------------------------------------------------------------------- the server


def raw_request(server, method: str, path: str, headers: dict[str, str], body: bytes = b"") -> tuple[int, dict]:
    """Send a request with exactly these headers (http.client adds none but Accept-Encoding)."""
    connection = http.client.HTTPConnection("127.0.0.1", server.server_address[1], timeout=30)
    connection.putrequest(method, path, skip_host=True, skip_accept_encoding=True)
    for name, value in headers.items():
        connection.putheader(name, value)
    connection.endheaders(body or None)
    response = connection.getresponse()
    answer = response.status, json.loads(response.read() or b"{}")
    connection.close()
    return answer


def test_a_foreign_host_is_refused_on_every_route(server):
    token = {"X-Scenegrep-Token": server.token}
    for host in ("evil.example", f"evil.example:{server.server_address[1]}", f"localhost:{server.server_address[1]}"):
        for path in ("/", "/api/traces", "/view/x"):
            status, body = raw_request(server, "GET", path, {"Host": host, **token})
            assert status == 403 and "answers only requests for" in body["error"], (host, path)
        post = {"Host": host, "Content-Type": "application/json", "Content-Length": "2", **token}
        assert raw_request(server, "POST", "/api/query", post, b"{}")[0] == 403
    status, _ = raw_request(server, "GET", "/api/traces", {"Host": server.address, **token})
    assert status == 200


def test_the_api_needs_the_token_of_the_page(server):
    status, page = fetch(server, "")
    assert status == 200 and f'data-token="{server.token}"'.encode() in page
    for token in (None, "guessed"):
        assert fetch(server, "api/traces", headers={"X-Scenegrep-Token": token})[0] == 403
        assert fetch(server, "api/query", SPRE, headers={"X-Scenegrep-Token": token})[0] == 403
    assert fetch(server, "api/traces")[0] == 200


def test_posts_from_other_origins_or_not_json_are_refused(server):
    def runs() -> list:
        return json.loads(fetch(server, "api/runs")[1])

    before = runs()
    text = {"kind": "spre", "text": "[[:bicycle:]]+", "options": {}}
    for extra in ({"Origin": "http://evil.example"}, {"Origin": "null"}, {"Content-Type": "text/plain"}):
        status, _ = fetch(server, "api/query", text, headers=extra)
        assert status in (403, 415), extra
    assert runs() == before
    assert fetch(server, "api/query", text, headers={"Origin": server.url.rstrip("/")})[0] == 200


def test_file_options_outside_the_dataset_are_refused_and_errors_name_no_absolute_path(server, real_dataset):
    for vocabulary in ("/etc/passwd", "../../etc/passwd", "catalog.duckdb/x"):
        request = {**SLOW, "options": {"window": "75", "vocabulary": vocabulary}}
        status, body = fetch(server, "api/query", request)
        assert status == 400 and "must name a file inside the dataset" in json.loads(body)["error"]
    status, body = fetch(server, "view/nope")
    assert status == 400 and json.loads(body)["error"] == "DATASET: the dataset has no trace 'nope'"
    assert str(real_dataset).encode() not in body


def test_a_scenic_programs_python_is_never_run(server, tmp_path):
    marker = tmp_path / "MARKER"
    program = f"model scenic.domains.driving.model\nopen({str(marker)!r}, 'w').write('ran')\nego = new Car\n"
    status, body = fetch(server, "api/query", {"kind": "scene", "text": program, "options": {}})
    assert status == 400 and "<query>:2" in json.loads(body)["error"] and not marker.exists()


def test_a_half_sent_or_negative_length_request_never_blocks_the_page(server, monkeypatch):
    monkeypatch.setattr(Handler, "timeout", 3.0)
    stalled = socket.create_connection(("127.0.0.1", server.server_address[1]))
    stalled.sendall(
        f"POST /api/query HTTP/1.1\r\nHost: {server.address}\r\nX-Scenegrep-Token: {server.token}\r\n"
        'Content-Type: application/json\r\nContent-Length: 1000\r\n\r\n{"kind"'.encode()
    )
    start = time.monotonic()
    assert fetch(server, "api/traces")[0] == 200
    assert time.monotonic() - start < 2.5  # a server answering one request at a time waits 3 s
    stalled.settimeout(10)
    assert stalled.recv(100) == b""  # dropped after the read timeout, unanswered
    stalled.close()
    negative = {"Host": server.address, "X-Scenegrep-Token": server.token, "Content-Type": "application/json"}
    status, body = raw_request(server, "POST", "/api/query", {**negative, "Content-Length": "-1"})
    assert status == 400 and "bad Content-Length" in body["error"]


def test_a_slow_query_is_stopped_at_the_time_limit_and_blocks_nothing(server):
    server.time_limit = 1.0
    answers: list = []
    slow = threading.Thread(target=lambda: answers.append((time.monotonic(), fetch(server, "api/query", HEAVY))))
    start = time.monotonic()
    slow.start()
    while not server.query_lock.locked() and time.monotonic() - start < 10:
        time.sleep(0.01)
    assert fetch(server, "api/traces")[0] == 200
    status, body = fetch(server, "api/query", SPRE)
    assert status == 409 and "another query is running" in json.loads(body)["error"], (answers, body[:300])
    slow.join(30)
    ended, (status, body) = answers[0]
    assert status == 408 and json.loads(body)["error"] == "the query ran longer than 1 s and was stopped"
    assert ended - start < 6.0  # the query alone takes tens of seconds
    server.time_limit = 300.0
    assert fetch(server, "api/query", SPRE)[0] == 200  # the next query runs


def test_the_stopped_query_leaves_no_process(real_dataset, monkeypatch):
    """The child and the workers it forked (one process group) are all gone after the limit."""
    groups: list[int] = []
    kill = limited._kill_group
    monkeypatch.setattr(limited, "_kill_group", lambda pid: (groups.append(pid), kill(pid)))
    spec = QuerySpec.of(HEAVY["kind"], HEAVY["text"], **HEAVY["options"])
    with pytest.raises(limited.QueryTimeout):
        limited.run_limited(real_dataset, spec, 2, 1.5)
    deadline = time.monotonic() + 5
    while _living(groups[0]) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert _living(groups[0]) == []


def _living(group: int) -> list[str]:
    """The processes of a process group that are not zombies (from /proc)."""
    found = []
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == group and fields[0] != "Z":
            found.append(pid)
    return found


def test_serve_compiles_scenic_programs_without_scenic_and_never_reaches_synth():
    """The server and the query compilers load neither Scenic's compiler (which would run the
    program's Python) nor scenegrep.synth (a fresh interpreter, so nothing else loaded them)."""
    script = (
        "import sys\n"
        "import scenegrep.view.serve\n"
        "from scenegrep.dataset.queries import QuerySpec, compiled\n"
        f"compiled(QuerySpec.of('scene', {SCENE_PROGRAM!r}))\n"
        f"compiled(QuerySpec.of('scenario', {SLOW['text']!r}, window='75'))\n"
        "print(sorted(m for m in sys.modules if m.startswith(('scenic', 'scenegrep.synth'))))\n"
    )
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "[]", done.stderr


def test_stopping_the_server_stops_a_running_query(real_dataset):
    """Ctrl-C reaches the server only (queries lead their own process groups): it kills them."""
    server = subprocess.Popen(
        [sys.executable, "-m", "scenegrep", "serve", str(real_dataset), "--port", "0", "-j", "2"],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(REPO / "src")},
    )
    try:
        url = re.search(r"http://127\.0\.0\.1:\d+/", server.stdout.readline()).group(0)
        page = urllib.request.urlopen(url, timeout=30).read().decode()
        token = re.search(r'data-token="([^"]+)"', page).group(1)
        headers = {"X-Scenegrep-Token": token, "Content-Type": "application/json"}
        request = urllib.request.Request(url + "api/query", json.dumps(SLOW).encode(), headers)
        threading.Thread(
            target=lambda: _ignore_errors(urllib.request.urlopen, request, timeout=60), daemon=True
        ).start()
        deadline = time.monotonic() + 20
        while len(_descendants(server.pid)) < 3 and time.monotonic() < deadline:  # fork server, query, workers
            time.sleep(0.1)
        started = _descendants(server.pid)
        assert len(started) >= 3
    finally:
        stopping = time.monotonic()
        server.send_signal(signal.SIGINT)
        server.wait(timeout=60)
    assert time.monotonic() - stopping < 3.0, "the server waited for the query"
    deadline = time.monotonic() + 5
    while [p for p in started if _alive(p)] and time.monotonic() < deadline:
        time.sleep(0.1)
    assert [p for p in started if _alive(p)] == []


def _ignore_errors(function, *args, **kwargs) -> None:
    with contextlib.suppress(OSError):
        function(*args, **kwargs)


def _stat(pid: str) -> list[str] | None:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None


def _descendants(root: int) -> set[str]:
    """The processes below ``root`` (from /proc)."""
    parents = {pid: fields[1] for pid in filter(str.isdigit, os.listdir("/proc")) if (fields := _stat(pid))}
    found, frontier = set(), {str(root)}
    while frontier:
        frontier = {pid for pid, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def _alive(pid: str) -> bool:
    fields = _stat(pid)
    return fields is not None and fields[0] != "Z"


@pytest.mark.parametrize("named", ["/etc/hostname.xodr", "../x.snet", "maps"])
def test_a_programs_param_map_must_name_a_file_inside_the_dataset(server, named):
    program = f"param map = {named!r}\n{SCENE_PROGRAM}"
    status, body = fetch(server, "api/query", {"kind": "scene", "text": program, "options": {}})
    assert status == 400
    assert json.loads(body)["error"].startswith("option 'param map' must name a file inside the dataset: ")
