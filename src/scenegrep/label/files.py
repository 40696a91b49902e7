"""Labelling inputs into a folder (``scenegrep label DATA... -o OUT``): every trace of an input is
read, labelled on its road map (its own, else ``--map``'s: :func:`scenegrep.readers.with_given_map`), written as
``OUT/<trace name>.parquet`` and counted in the per-class statistics.

File names are the trace names made file-name safe (:func:`scenegrep.writers.file_names.file_stem`),
``-2``, ``-3``, ... appended to a name already written by this labelling, so no trace overwrites
another.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from .. import readers
from ..errors import UserError, at
from ..model.layers import UnknownLayers
from ..writers import write_trace_parquet
from ..writers.file_names import file_stem
from .config import LabelConfig
from .labeller import label_trace
from .statistics import LabelStatistics


@dataclass
class FolderLabelling:
    """Labels inputs into the folder ``output`` with ``config`` (see the module docstring);
    ``map_path`` the road map of traces without one (a trace with its own map and a ``map_path``
    is an error), behaviours kept from
    ``min_confidence`` (None: the config's), the ``unknown_layers`` choice."""

    output: Path
    config: LabelConfig
    map_path: str | None = None
    min_confidence: float | None = None
    unknown_layers: UnknownLayers | None = None
    statistics: LabelStatistics = field(default_factory=LabelStatistics)
    names: set[str] = field(default_factory=set)

    def __post_init__(self) -> None:
        if self.min_confidence is not None and not 0.0 <= self.min_confidence <= 1.0:
            raise UserError("--min-confidence must be between 0 and 1")
        self.output = Path(self.output)
        self.output.mkdir(parents=True, exist_ok=True)

    def label_input(self, path: str, on_trace: Callable[[], None] = lambda: None) -> None:
        """Label and write every trace of the input at ``path``, calling ``on_trace`` after each;
        a labeller's error without a place is placed at ``path``."""
        for trace in readers.read_traces(path):
            trace = readers.with_given_map(trace, self.map_path)
            road_map = readers.read_map(trace.map_source) if trace.map_source else None
            try:
                labelled = label_trace(trace, road_map, self.config, self.min_confidence, self.unknown_layers).trace
            except UserError as exc:
                raise exc if exc.location else UserError(exc.message, at(path)) from None
            write_trace_parquet(labelled, self.output / f"{self._unique(trace.name)}.parquet")
            self.statistics.add(labelled)
            on_trace()

    def _unique(self, name: str) -> str:
        """A file-name-safe version of a trace name, distinct from those already written."""
        base = file_stem(name)
        candidate, k = base, 1
        while candidate in self.names:
            k += 1
            candidate = f"{base}-{k}"
        self.names.add(candidate)
        return candidate
