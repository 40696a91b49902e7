"""``scenegrep info``: works on every real input; a truncated copy of each gives one clear line, exit 2."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from scenegrep.cli.main import main
from tests.readers.real_inputs import REAL_MAPS, REAL_TRACES

pytestmark = pytest.mark.real_data


@pytest.mark.parametrize("relative, expected", REAL_TRACES + REAL_MAPS)
def test_info_json_on_real_inputs(real_data, capsys, relative, expected):
    assert main(["info", "--json", str(real_data / relative)]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["format"] == expected
    for trace in summary["traces"]:
        assert trace["frames"] > 0 and trace["objects"] > 0
        assert sum(trace["objects_per_class"].values()) == trace["objects"]
    assert summary["maps"] and all(m["lanes"] > 10 for m in summary["maps"])


def test_info_text_names_the_facts(real_data, capsys):
    assert main(["info", str(real_data / REAL_TRACES[0][0])]) == 0
    out = capsys.readouterr().out
    assert "156 frames, 15.50 s at 10.0 Hz, 115 objects, ego ego" in out
    assert "183 lanes (73 in intersections)" in out
    assert "0 curbs; unknown (not published): curb, shoulder, sidewalk;" in out  # AV2 maps


def _truncate(source, target):
    if source.is_dir():
        shutil.copytree(source, target)
        for name in ("annotations.feather",):
            if (target / name).exists():
                data = (target / name).read_bytes()
                (target / name).write_bytes(data[: len(data) // 2])
        for parquet in target.glob("scenario_*.parquet"):
            data = parquet.read_bytes()
            parquet.write_bytes(data[: len(data) // 2])
        return target / ("annotations.feather" if (target / "annotations.feather").exists() else "")
    data = source.read_bytes()
    target.write_bytes(data[: len(data) // 2])
    return target


@pytest.mark.parametrize("relative, expected", REAL_TRACES + REAL_MAPS)
def test_truncated_copy_gives_one_line_error(real_data, tmp_path, capsys, relative, expected):
    source = real_data / relative
    target = tmp_path / source.name
    damaged = _truncate(source, target)
    assert main(["info", str(target)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("scenegrep: error: ")
    assert str(damaged).rstrip("/") in err[0] or str(target) in err[0]
    assert "Traceback" not in err[0]


def test_usage_errors_and_help():
    out = subprocess.run([sys.executable, "-m", "scenegrep", "info"], capture_output=True, text=True)
    assert out.returncode == 2 and out.stderr.count("\n") == 1 and "PATH" in out.stderr
    out = subprocess.run([sys.executable, "-m", "scenegrep", "--help"], capture_output=True, text=True)
    assert out.returncode == 0 and "info" in out.stdout


def test_closed_stdout_is_not_a_failed_input():
    """`scenegrep info MANY | head -1`: the reader leaving stops the command quietly (exit 0); no
    input is reported as failed because stdout was closed."""
    sample = sorted(str(p) for p in Path("examples/sample").glob("*.parquet"))
    process = subprocess.Popen(
        [sys.executable, "-m", "scenegrep", "info", *sample],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    assert process.stdout.readline().startswith(b"examples/sample/")
    process.stdout.close()
    stderr = process.stderr.read().decode()
    assert process.wait(timeout=60) == 0
    assert "failed" not in stderr
