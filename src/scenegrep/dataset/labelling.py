"""Which behaviour labels a scenario query reads: those made under the query's choice for unknown map layers.

The labeller's Cross rule depends on the choice for map layers a map does not publish
(:mod:`scenegrep.model.layers`): nuScenes maps publish no crosswalks, so a trace labelled under
``strict`` has other labels than under ``permissive``. Ingest labels each trace without behaviour
labels once, under the ingest's choice, and records that choice in the catalog's ``traces`` table
(column ``labelled_under``, see :func:`recorded_choice`):

- NULL: ingest did not label the trace: its labels are its own (never re-labelled), or it has
  none (a query labels it, as a query over files does);
- ``'permissive'``, ``'strict'`` or ``'none'`` (no choice): the choice it was labelled under;
- ``'unknown'`` (:data:`UNKNOWN`): a catalog written before the column existed (the column's
  default fills its rows). Such a trace is re-labelled when its labels are the labeller's (their
  vocabulary is :data:`scenegrep.label.VOCABULARY`), since its choice cannot be told; labels of
  another vocabulary are the trace's own and are kept.

A query over a dataset re-labels a trace labelled under another choice than its own with
:func:`labelled`, the function a query over files labels its traces with, so both modes read the
same labels.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..model import LabelTrace, RoadMap
from ..model.layers import UnknownLayers

COLUMN = "labelled_under"
"""The column of the catalog's ``traces`` table that records the choice a trace was labelled under."""

NO_CHOICE = "none"
"""The recorded choice of labels made without a choice (an unknown layer a decision needed was an error)."""

UNKNOWN = "unknown"
"""The recorded choice of a trace in a catalog written before :data:`COLUMN` existed."""


def recorded_choice(mode: str | None) -> str:
    """How the catalog records labels made under the choice ``mode`` (None: no choice)."""
    return NO_CHOICE if mode is None else mode


def relabels(labelled_under: str | None, mode: str | None, trace: LabelTrace) -> bool:
    """Whether a query under the choice ``mode`` must label ``trace`` again: it has no labels, or
    ingest labelled it under another choice (``labelled_under``, see the module docstring)."""
    if trace.behaviours is None:
        return True
    if labelled_under is None:
        return False
    if labelled_under == UNKNOWN:
        from ..label import VOCABULARY

        return tuple(trace.behaviours.vocabulary) == tuple(VOCABULARY)
    return labelled_under != recorded_choice(mode)


def labelled(
    trace: LabelTrace, road_map: RoadMap | None, choice: UnknownLayers | None, labelled_under: str | None = None
) -> LabelTrace:
    """``trace`` with the behaviour labels a query under ``choice`` reads: its own labels, or those
    ingest made under the same choice, else labelled now with ``scenegrep label``'s labeller on
    ``road_map`` (the trace's own map) under ``choice``."""
    mode = None if choice is None else choice.mode
    if not relabels(labelled_under, mode, trace):
        return trace
    from ..label import label_trace

    return label_trace(trace, road_map, unknown_layers=choice).trace


def catalog_value(row: dict[str, Any]) -> str | None:
    """The recorded choice of a ``traces`` row (:data:`UNKNOWN` when the catalog has no such column)."""
    return row.get(COLUMN, UNKNOWN)


def as_queried(root: Path, trace_id: str, trace: LabelTrace, road_map: RoadMap | None, mode: str | None) -> LabelTrace:
    """A trace of the dataset at ``root`` (read with its own ``road_map``) with the labels a scenario
    query under the choice ``mode`` read (for views of its results)."""
    from .catalog import Catalog

    with Catalog(root, read_only=True) as catalog:
        rows = catalog.sql("SELECT * FROM traces WHERE trace_id = ?", [trace_id]).to_pylist()
    recorded = catalog_value(rows[0]) if rows else UNKNOWN
    return labelled(trace, road_map, UnknownLayers(mode), recorded)
