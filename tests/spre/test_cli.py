"""``scenegrep spre``: outputs, options, live streaming on stdin, errors."""

import json
import subprocess
import sys
import time

import pytest

from scenegrep.cli.main import main
from scenegrep.readers.strem_json import decode


def run(args, capsys):
    code = main(["spre", *args])
    out, err = capsys.readouterr()
    return code, out.splitlines(), err


def test_text_json_and_export(conformance_dir, capsys):
    seq = str(conformance_dir / "strem/data/noncontig.json")
    code, lines, _ = run(["[[:car:]]{2}", seq], capsys)
    assert (code, lines) == (0, [f"{seq}#noncontig:10-20"])
    assert run(["--compat", "strem", "[[:car:]]{2}", seq], capsys)[:2] == (0, [f"{seq}:10..21"])
    code, lines, _ = run(["--json", "[[:car:]]{2}", seq], capsys)
    record = json.loads(lines[0])
    assert (record["start_frame"], record["end_frame"], record["status"]) == (10, 20, "match")
    code, lines, _ = run(["--export", "[[:car:]]{2}", seq], capsys)
    exported = decode(lines[0].encode(), "<export>", "x")
    assert exported.frame_index.tolist() == [10, 20] and len(exported.images.boxes) == 2


def test_exit_codes_quiet_and_max_count(conformance_dir, capsys):
    seq = str(conformance_dir / "strem/data/seq_a.json")
    assert run(["[[:truck:]]", seq], capsys)[:2] == (1, [])
    assert run(["-q", "[[:car:]]", seq], capsys)[:2] == (0, [])
    assert run(["-m", "1", "[[:car:]]", seq], capsys)[:2] == (0, [f"{seq}#seq_a:0-0"])
    assert run(["--compat", "strem", "-m", "1", "[[:car:]]", seq], capsys)[:2] == (0, [f"{seq}:0..1"])
    code, _, err = run(["[[:car:]", seq], capsys)
    assert code == 2 and err.startswith("scenegrep: error: <query>:1:9: ") and "^" in err


def test_bad_file_is_a_one_line_failure_and_the_others_run(conformance_dir, capsys):
    bad, good = (str(conformance_dir / f"strem/data/{name}.json") for name in ("fmt_missing_image", "seq_a"))
    code, lines, err = run(["[[:car:]]", bad, good], capsys)
    (failed,) = [line for line in err.splitlines() if "missing field `image`" in line]
    assert code == 3 and failed.startswith("scenegrep: failed: fmt_missing_image.json: ") and lines
    assert "Traceback" not in err
    code, _, err = run(["--compat", "strem", "[[:car:]]", bad, good], capsys)  # STREM stops at the bad file
    assert code == 2 and err.count("\n") == 1 and "missing field `image`" in err


def test_online_stdin_reports_each_match_as_its_frame_arrives(conformance_dir):
    doc = json.loads((conformance_dir / "strem/data/seq_a.json").read_text())
    process = subprocess.Popen(
        [sys.executable, "-m", "scenegrep", "spre", "--compat", "strem", "--online", "[[:car:]]*"],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        bufsize=1,
    )
    try:
        for frame in doc["frames"][:2]:
            process.stdin.write(json.dumps({"version": "0.2.0", "frames": [frame]}) + "\n")
            process.stdin.flush()
            started = time.monotonic()
            line = process.stdout.readline().strip()
            assert time.monotonic() - started < 20
            assert line == f"0..{frame['index'] + 1}"
    finally:
        process.stdin.close()
        process.wait(timeout=20)
    assert process.returncode == 0


def test_online_stdin_constant_state(tmp_path):
    """Many single-frame documents through stdin: the match grows, the answer stays right."""
    frame = {
        "index": 0,
        "samples": [
            {
                "type": "@stremf/sample/detection",
                "channel": "c",
                "image": {"path": "p", "dimensions": {"width": 1, "height": 1}},
                "annotations": [
                    {
                        "class": "car",
                        "score": 1.0,
                        "bbox": {
                            "type": "@stremf/bbox/aabb",
                            "region": {"center": {"x": 0, "y": 0}, "dimensions": {"w": 1, "h": 1}},
                        },
                    }
                ],
            }
        ],
    }
    feed = "".join(json.dumps({"version": "0.2.0", "frames": [{**frame, "index": i}]}) + "\n" for i in range(3000))
    out = subprocess.run(
        [sys.executable, "-m", "scenegrep", "spre", "--online", "[[:car:]]*"],
        input=feed,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()
    assert len(out) == 3000 and out[-1] == "-:0-2999"


@pytest.mark.parametrize(
    "args, status, message",
    [
        (["--space", "topdown", "[[:car:]]"], 2, "top-down"),  # the stream has no objects: the lone input fails
        (["--online", "--compat", "strem", "[[:car:]]{0}"], 2, "0 frames online"),
    ],
)
def test_option_errors(conformance_dir, capsys, args, status, message):
    code, _, err = run([*args, str(conformance_dir / "strem/data/seq_a.json")], capsys)
    assert code == status and message in err
