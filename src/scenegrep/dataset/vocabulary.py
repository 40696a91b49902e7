"""The names a query's traces have, and the warnings for the names a query uses that none has.

A run (over files or over a dataset) gathers the (class, kind, layer) triples of the traces it
searched, pruned ones included (from their statistics: the catalog's ``frame_counts``), and the
image channels of the traces it read. :func:`query_warnings` then names each class of a SpRE, image
channel of ``--channel``, or Scenic program object's kinds that no searched trace has
(:mod:`scenegrep.spre.vocabulary`, :mod:`scenegrep.scene.vocabulary`): one line each, with the
names the data has. Nothing is said when no trace was read (every one failed).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

from ..model import LabelTrace
from .catalog import Catalog
from .queries import QuerySpec

SPACE_LAYERS = {"image": ("images",), "topdown": ("objects",), None: ("images", "objects")}
"""The ``frame_counts`` layers a SpRE searches, by its ``space`` option."""


@dataclass
class Vocabulary:
    """The (class, kind, layer) triples and image channels of the traces searched so far, and
    how many traces they came from."""

    classes: set[tuple[str, str, str]] = field(default_factory=set)
    channels: set[str] = field(default_factory=set)
    traces: int = 0

    def add_counts(self, frame_counts: Any, traces: int = 1) -> None:
        """Add the triples of a ``frame_counts`` table (statistics or catalog) of ``traces`` traces."""
        columns = frame_counts.select(["category", "kind", "layer"]).to_pydict()
        self.classes.update(zip(columns["category"], columns["kind"], columns["layer"]))
        self.traces += traces

    def add_catalog(self, catalog: Catalog) -> None:
        """Add every trace of a dataset's catalog."""
        table = catalog.sql("SELECT DISTINCT category, kind, layer FROM frame_counts")
        (traces,) = catalog.rows("SELECT count(*) FROM traces")[0]
        self.add_counts(table, traces)

    def add_channels(self, channels: Iterable[str]) -> None:
        self.channels.update(channels)


def channels_of(trace: LabelTrace) -> tuple[str, ...]:
    """The image channels a trace has samples of."""
    return () if trace.images is None else tuple(trace.images.samples.channels)


def query_warnings(spec: QuerySpec, query: Any, vocabulary: Vocabulary) -> tuple[str, ...]:
    """The warnings for the names ``query`` (the compiled ``spec``) uses that no searched trace has."""
    if not vocabulary.traces:
        return ()
    if spec.kind == "spre":
        from ..spre.vocabulary import unknown_channels, unknown_classes

        layers = SPACE_LAYERS[spec.option("space")]
        pairs = [(category, kind) for category, kind, layer in vocabulary.classes if layer in layers]
        found = unknown_classes(query.tree, query.compat, pairs)
        if spec.option("channels"):
            found += unknown_channels(spec.option("channels"), vocabulary.channels)
        return tuple(found)
    from ..scene.vocabulary import unknown_kinds

    program = query.program if spec.kind == "scene" else query.scene.program
    kinds = [kind for _, kind, layer in vocabulary.classes if layer == "objects"]
    return tuple(unknown_kinds(program.objects, kinds))
