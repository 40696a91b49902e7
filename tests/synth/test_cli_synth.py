"""``scenegrep synth``: files, manifest, map paths, noise options and one-line errors."""

import json

import numpy as np
import pytest

from scenegrep.cli.main import main
from scenegrep.readers import read_trace

pytestmark = pytest.mark.slow

HEADER = "model scenic.simulators.newtonian.driving_model\n"
CRUISE = (
    HEADER + "ego = new Car with behavior FollowLaneBehavior(target_speed=8)\nparked = new Car ahead of ego by 10\n"
)


def synth(*args, capsys):
    code = main(["synth", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err.strip().splitlines()


@pytest.fixture
def programs(tmp_path):
    (tmp_path / "cruise.scenic").write_text(CRUISE)
    (tmp_path / "bad.scenic").write_text(HEADER + "ego = new Car with behavior\n")
    return tmp_path


def test_writes_one_trace_per_run_and_a_manifest(programs, maps_dir, scenic_cache, capsys):
    out = programs / "out"
    town01 = maps_dir / "Town01.xodr"
    code, stdout, err = synth(
        programs / "cruise.scenic", "--map", town01, "--runs", 3, "--steps", 20, "-o", out, "--seed", 4, capsys=capsys
    )
    assert code == 0 and stdout == "" and err[-1] == f"scenegrep: wrote 3 traces and manifest.json to {out}"
    names = [f"cruise-{k:03d}.parquet" for k in range(3)]
    assert sorted(p.name for p in out.iterdir()) == [*names, "manifest.json"]
    manifest = json.loads((out / "manifest.json").read_text())
    assert [e["file"] for e in manifest["traces"]] == names
    entry = manifest["traces"][1]
    assert (entry["program"], entry["seed"], entry["run"], entry["steps"], entry["frames"]) == (
        "../cruise.scenic",
        4,
        1,
        20,
        20,
    )
    assert (out / entry["map"]).resolve() == town01.resolve() and entry["noise"] is None
    trace = read_trace(out / names[1])
    assert trace.attributes["run_seed"] == entry["run_seed"] and trace.n_frames == 20
    assert trace.objects.id.tolist() == ["ego", "obj1"] and entry["objects"] == {"ego": "Car", "obj1": "Car"}
    assert trace.map_source.format == "opendrive" and trace.map_source.path == str(town01)


def test_noise_options_and_manifest_merge(programs, maps_dir, scenic_cache, capsys):
    out = programs / "out"
    common = ["--map", maps_dir / "Town01.xodr", "--steps", 30, "-o", out, "-q"]
    assert synth(programs / "cruise.scenic", "--runs", 1, *common, capsys=capsys) == (0, "", [])
    (programs / "other.scenic").write_text(CRUISE)
    noisy = ["--noise-position", 0.5, "--drop-frames", 0.3, "--confuse-behaviours", 0.5, "--noise-seed", 2]
    assert synth(programs / "other.scenic", "--runs", 2, *common, *noisy, capsys=capsys) == (0, "", [])
    manifest = json.loads((out / "manifest.json").read_text())
    files = [e["file"] for e in manifest["traces"]]
    assert files == ["cruise-000.parquet", "other-000.parquet", "other-001.parquet"]
    noise = manifest["traces"][1]["noise"]
    assert (noise["position"], noise["drop_frames"], noise["confuse_behaviours"], noise["seed"]) == (0.5, 0.3, 0.5, 2)
    clean, noisy_trace = read_trace(out / files[0]), read_trace(out / files[1])
    assert noisy_trace.n_frames < 30 and noisy_trace.attributes["noise"] == noise
    kept = np.searchsorted(clean.frame_index, noisy_trace.frame_index)
    assert not np.allclose(noisy_trace.dense("x"), clean.dense("x")[kept])
    assert "LaneChange" in noisy_trace.behaviours.vocabulary


def test_bad_program_is_one_line_at_line_and_column(programs, maps_dir, capsys):
    program = programs / "bad.scenic"
    code, _, err = synth(
        program, "--map", maps_dir / "Town01.xodr", "--runs", 1, "--steps", 5, "-o", programs / "out", capsys=capsys
    )
    assert (
        code == 2
        and err[-1]
        == f"scenegrep: error: {program}:2:28: Scenic rejected the program: ScenicParseError: invalid syntax"
    )
    assert not (programs / "out").exists()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--runs", 0], "--runs, --steps and --max-iterations must be at least 1"),
        (["--drop-frames", 1.5], "drop_frames must lie in [0, 1)"),
        (["--map", "nowhere.xodr"], "nowhere.xodr: no such file (expected an OpenDRIVE .xodr file)"),
    ],
)
def test_option_errors(programs, maps_dir, capsys, args, message):
    base = {"--map": maps_dir / "Town01.xodr", "--runs": 1, "--steps": 5, "-o": programs / "out"}
    base.update(dict(zip(args[::2], args[1::2])))
    code, _, err = synth(programs / "cruise.scenic", *[v for kv in base.items() for v in kv], capsys=capsys)
    assert code == 2 and len(err) == 1 and message in err[0]
