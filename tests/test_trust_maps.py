"""Data never runs code: a hostile Scenic ``.snet`` (a pickle whose loading writes a marker file),
named by a trace's map entry, by a program's ``param map``, by ``synth --map``, or lying beside
the ``.xodr`` a trace names, is never unpickled by any command; naming one is a one-line error."""

from __future__ import annotations

import gzip
import hashlib
import json
import os
import pickle
import shutil
import struct
from pathlib import Path

import pytest

from scenegrep.cli.main import main

pytestmark = pytest.mark.slow

REFUSED = "not an OpenDRIVE map: expected a .xodr file (Scenic .snet caches are pickles and are never read)"
SCENE = "model scenic.domains.driving.model\nego = new Car on road\n"
SCENARIO = "model scenic.simulators.newtonian.driving_model\nego = new Car on road\n"


class Payload:
    """Unpickling it writes ``marker`` (the code a hostile pickle would run)."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return (Path.write_text, (self.marker, "code from a data file ran"))


def hostile_snet(path: Path, marker: Path, xodr: Path | None = None) -> Path:
    """A ``.snet`` in Scenic's own layout (format version, digests of the map and of the default
    map options, gzipped pickle) that Scenic's ``Network.fromFile`` would accept as the cache of
    ``xodr`` (or load directly when named), and whose pickle writes ``marker``."""
    from scenic.core.serialization import deterministicHash
    from scenic.domains.driving.roads import Network

    digest = hashlib.blake2b(xodr.read_bytes()).digest() if xodr else bytes(64)
    header = struct.pack("<I", Network._currentFormatVersion()) + digest + deterministicHash({}, digest_size=8)
    path.write_bytes(header + gzip.compress(pickle.dumps(Payload(marker))))
    return path


def trace_doc(map_path: str) -> dict:
    """A two-frame scenegrep JSON trace of one car whose map entry names ``map_path``."""
    car = {"position": [92.0, 3.0], "heading": 1.57, "velocity": [-5.0, 0.0]}
    return {
        "scenegrep": "trace",
        "version": 1,
        "name": "hostile",
        "ego": "car",
        "frame_interval": 0.1,
        "map": {"path": map_path, "format": "opendrive"},
        "objects": {"car": {"class": "Car", "size": [4.5, 2.0]}},
        "frames": [{"objects": {"car": car}}, {"objects": {"car": car}}],
    }


@pytest.fixture
def planted(tmp_path, maps_dir, scenic_cache):
    """A folder with hostile .snet files: ``x.snet`` (named by ``snet.json`` and by the programs'
    ``param map``), ``x``, the same without suffix (Scenic's fromFile would try ``x.snet``), and
    ``Town01.snet`` beside a copy of Town01.xodr (named by ``town.json``)."""
    marker = tmp_path / "MARKER"
    hostile_snet(tmp_path / "x.snet", marker)
    shutil.copyfile(tmp_path / "x.snet", tmp_path / "x")
    shutil.copyfile(maps_dir / "Town01.xodr", tmp_path / "Town01.xodr")
    hostile_snet(tmp_path / "Town01.snet", marker, tmp_path / "Town01.xodr")
    for name, map_path in (("snet", "x.snet"), ("bare", "x"), ("town", "Town01.xodr")):
        (tmp_path / f"{name}.json").write_text(json.dumps(trace_doc(map_path)))
    nomap = trace_doc("x.snet")
    del nomap["map"]
    (tmp_path / "nomap.json").write_text(json.dumps(nomap))
    (tmp_path / "scene.scenic").write_text(SCENE)
    (tmp_path / "scenario.scenic").write_text(SCENARIO)
    (tmp_path / "param_scene.scenic").write_text("param map = 'x.snet'\n" + SCENE)
    (tmp_path / "param_scenario.scenic").write_text("param map = 'x.snet'\n" + SCENARIO)
    return tmp_path, marker


def test_the_planted_snet_runs_code_when_scenic_loads_it(tmp_path):
    """The payload is live: Scenic's own loader, given the file, writes the marker."""
    from scenic.domains.driving.roads import Network

    marker = tmp_path / "MARKER"
    snet = hostile_snet(tmp_path / "x.snet", marker)
    Network.fromFile(str(snet))
    assert marker.read_text() == "code from a data file ran"


def run(folder: Path, capsys, *args: str) -> tuple[int, list[str]]:
    """Run a command line inside ``folder`` (relative names resolve there): the exit code and
    the error lines on stderr, a failed trace's included (notes and summaries left out)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(folder)
        code = main(list(args))
    err = capsys.readouterr().err.strip().splitlines()
    assert not any("Traceback" in line for line in err), err
    return code, [line for line in err if line.startswith(("scenegrep: error: ", "scenegrep: failed: "))]


@pytest.mark.parametrize("trace", ["snet.json", "bare.json"])
@pytest.mark.parametrize(
    "command",
    [
        ["info", "{trace}"],
        ["label", "{trace}", "-o", "labelled"],
        ["scene", "scene.scenic", "{trace}"],
        ["scenario", "scenario.scenic", "{trace}", "--window", "2"],
        ["show", "{trace}", "-o", "view.png"],
        ["ingest", "{trace}", "--into", "fleet"],
    ],
)
def test_a_trace_naming_a_snet_as_its_map_is_refused_by_every_command(planted, capsys, trace, command):
    folder, marker = planted
    code, err = run(folder, capsys, *[part.format(trace=trace) for part in command])
    map_name = "x.snet" if trace == "snet.json" else "x"
    assert code in (2, 3) and len(err) == 1 and err[0].endswith(f"{map_name}: {REFUSED}"), err
    assert not marker.exists()


@pytest.mark.parametrize(
    "command",
    [
        ["scene", "param_scene.scenic", "nomap.json"],
        ["scenario", "param_scenario.scenic", "nomap.json", "--window", "2"],
        ["synth", "scenario.scenic", "--map", "x.snet", "--runs", "1", "--steps", "2", "-o", "out"],
    ],
)
def test_a_program_or_option_naming_a_snet_as_the_map_is_refused(planted, capsys, command):
    folder, marker = planted
    code, err = run(folder, capsys, *command)
    assert code in (2, 3) and err[-1].endswith(f"x.snet: {REFUSED}") and len(err) == 1, err
    assert not marker.exists()


def test_a_spre_query_never_reads_the_map(planted, capsys):
    folder, marker = planted
    code, err = run(folder, capsys, "spre", "[[:car:]]+", "snet.json")
    assert code == 0 and err == []
    assert not marker.exists()


@pytest.mark.parametrize(
    "command",
    [
        ["info", "town.json"],
        ["scene", "scene.scenic", "town.json"],
        ["show", "town.json", "-o", "view.png"],
        ["synth", "scenario.scenic", "--map", "Town01.xodr", "--runs", "1", "--steps", "2", "-o", "out", "-q"],
    ],
)
def test_a_snet_beside_the_xodr_is_never_read(planted, capsys, command):
    """The .xodr is parsed (or scenegrep's own cache used); the .snet beside it stays unread."""
    folder, marker = planted
    code, err = run(folder, capsys, *command)
    assert code in (0, 1) and err == [], err
    assert not marker.exists()


def test_synth_gives_scenic_only_a_copy_of_the_map_in_scenegreps_cache(planted, capsys):
    """Scenic reads a copy in the cache, beside the .snet scenegrep wrote there (never Scenic)."""
    from scenegrep.synth._scenic import map_params

    folder, _ = planted
    params = map_params(folder / "Town01.xodr")
    copy = Path(params["map"])
    assert params["map_options"] == {"useCache": True, "writeCache": False}
    assert copy.parent.parent.parent == Path(os.environ["SCENEGREP_CACHE"])
    assert copy.read_bytes() == (folder / "Town01.xodr").read_bytes() and copy.with_suffix(".snet").is_file()


def test_a_snet_named_as_any_map_or_file_of_a_wrong_kind_is_one_line(planted, capsys):
    folder, marker = planted
    (folder / "maps.xodr").mkdir()
    os.mkfifo(folder / "fifo.xodr")
    for name in ("maps", "fifo"):
        (folder / f"{name}.json").write_text(json.dumps(trace_doc(f"{name}.xodr")))
    for args, message in (
        (["info", "x.snet"], "x.snet: unrecognised input format"),
        (["scene", "scene.scenic", "town.json", "--map", "x.snet"], "x.snet: unrecognised input format"),
        (["info", "maps.json"], "maps.xodr: is a directory, expected a road map (opendrive)"),
        (["info", "fifo.json"], "fifo.xodr: not a regular file (a device, fifo or socket), expected a road map"),
        (["info", "fifo.xodr"], "fifo.xodr: not a regular file (a device, fifo or socket), expected a trace or map"),
    ):
        code, err = run(folder, capsys, *args)
        assert code == 2 and len(err) == 1 and message in err[0], err
    assert not marker.exists()


def test_a_parquet_traces_map_path_is_relative_to_the_trace_never_the_working_directory(planted, capsys):
    """``label`` stores the map relative to its output; a map named only in the working
    directory is not picked up from there."""
    from scenegrep.readers import read_trace

    folder, marker = planted
    assert run(folder, capsys, "label", "town.json", "-o", "out/labelled")[0] == 0
    written = folder / "out" / "labelled" / "hostile.parquet"
    assert read_trace(written).map_source.path == str(folder / "Town01.xodr")
    moved = folder / "elsewhere"
    moved.mkdir()
    shutil.move(written, moved / "hostile.parquet")
    code, err = run(folder, capsys, "info", "elsewhere/hostile.parquet")
    missing = "../Town01.xodr: no such file (expected a road map (opendrive))"  # not ./Town01.xodr
    assert code == 2 and err == [f"scenegrep: error: {missing}"]
    assert not marker.exists()


def test_a_trace_path_of_a_named_format_must_be_a_regular_file(tmp_path):
    """Even with its format named (as the dataset engine names it), a fifo is refused unread."""
    from scenegrep import readers
    from scenegrep.errors import UserError

    os.mkfifo(tmp_path / "t.parquet")
    with pytest.raises(
        UserError, match=r"t\.parquet: not a regular file .*expected a trace file \(scenegrep-parquet\)"
    ):
        readers.read_trace(tmp_path / "t.parquet", "scenegrep-parquet")


def test_without_a_writable_cache_scenic_reads_the_xodr_with_its_snet_cache_off(planted, monkeypatch):
    """The fallback never lets Scenic's ``Network.fromFile`` look at a ``.snet``."""
    from scenegrep.synth._scenic import NO_SNET, map_params

    folder, _ = planted
    (folder / "not-a-folder").write_text("")
    monkeypatch.setenv("SCENEGREP_CACHE", str(folder / "not-a-folder"))
    params = map_params(folder / "Town01.xodr")
    assert params == {"map": str(folder / "Town01.xodr"), "map_options": NO_SNET}
    assert NO_SNET == {"useCache": False, "writeCache": False}


def test_synth_says_that_scenic_runs_the_programs_python(capsys):
    with pytest.raises(SystemExit):
        main(["synth", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "Scenic runs the program's Python code with your rights" in text
    assert "never a .snet file beside it" in text
