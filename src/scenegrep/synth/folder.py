"""The output folder of ``scenegrep synth``: simulated traces and ``manifest.json``.

Each trace is written as ``DIR/<trace name>.parquet`` (scenegrep Parquet, atomically, replacing a
file of the same name) with its map path relative to the working directory as given, which the
trace writer stores relative to the file, so the folder and the map can move together. The
manifest lists every trace written into DIR (entries of other programs written there before are
kept; those of rewritten files are replaced), with paths relative to DIR; it is rewritten
(atomically) after the traces, also when a later run fails, so that it lists what was written.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..errors import UserError, at
from ..model import LabelTrace, MapSource

MANIFEST = "manifest.json"
MANIFEST_FORMAT = "scenegrep-synth-manifest"


@dataclass(frozen=True)
class SynthFolder:
    """An output folder (created when the first trace is written) and its manifest's entries so far."""

    path: Path
    previous: tuple[dict[str, Any], ...]

    @classmethod
    def open(cls, path: str | Path) -> SynthFolder:
        """The folder at ``path``; UserError when it is a file or holds a manifest that is not one
        of ``synth``'s (checked before any simulation runs)."""
        path = Path(path)
        if path.exists() and not path.is_dir():
            raise UserError("not a directory", at(path))
        return cls(path, tuple(_read_manifest(path / MANIFEST)))

    def write(self, traces: Iterable[LabelTrace], program: str | Path, map_path: str | Path) -> int:
        """Write each trace of ``program``'s runs on the OpenDRIVE map at ``map_path``, then the
        manifest (see the module docstring); the number of traces written."""
        from ..writers import write_trace_parquet

        stored_map = MapSource(os.path.relpath(map_path), "opendrive")
        entries: list[dict[str, Any]] = []
        try:
            for trace in traces:
                file = self.path / f"{trace.name}.parquet"
                written = write_trace_parquet(replace(trace, map_source=stored_map), file)
                entries.append(_entry(written.name, trace, self._relative(program), self._relative(map_path)))
        finally:
            if entries:
                self._write_manifest(entries)
        return len(entries)

    def _relative(self, path: str | Path) -> str:
        """A path as seen from the folder."""
        return os.path.relpath(Path(path).absolute(), self.path.absolute())

    def _write_manifest(self, entries: list[dict[str, Any]]) -> None:
        """The previous entries of other files, then the new ones, by file name."""
        from ..writers.atomic import atomic_path

        written = {e["file"] for e in entries}
        kept = [e for e in self.previous if e.get("file") not in written]
        doc = {
            "format": MANIFEST_FORMAT,
            "paths": "relative to this file's directory",
            "traces": sorted(kept + entries, key=lambda e: e["file"]),
        }
        with atomic_path(self.path / MANIFEST) as tmp:
            tmp.write_text(json.dumps(doc, indent=1) + "\n")


def _entry(file: str, trace: LabelTrace, program: str, map_path: str) -> dict[str, Any]:
    """The manifest entry of one written trace (``program`` and ``map_path`` relative to DIR)."""
    a = trace.attributes
    return {
        "file": file,
        "program": program,
        "map": map_path,
        "seed": a["seed"],
        "run": a["run"],
        "run_seed": a["run_seed"],
        "steps": a["steps"],
        "frames": trace.n_frames,
        "objects": dict(zip(trace.objects.id.tolist(), trace.objects.category.tolist())),
        "rejected_simulations": a["rejected_simulations"],
        "noise": a.get("noise"),
    }


def _read_manifest(path: Path) -> list[dict[str, Any]]:
    """The entries of an existing manifest (none when there is no file)."""
    if not path.exists():
        return []
    try:
        doc = json.loads(path.read_text())
        if doc.get("format") != MANIFEST_FORMAT:
            raise ValueError
        return list(doc["traces"])
    except (OSError, ValueError, AttributeError, KeyError, TypeError):
        raise UserError("not a scenegrep synth manifest; move it away or choose another -o DIR", at(path)) from None
