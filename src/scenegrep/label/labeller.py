"""Behaviour labels for every object of a trace, from its tracks and the road map.

:func:`label_trace` gathers the evidence (:mod:`.evidence`), scores every behaviour
(:mod:`.rules`) and keeps as an observation's label set every behaviour whose confidence is at
least the minimum confidence (seed 000's thresholding of a behaviour predictor); a set is never
empty: when no behaviour reaches the minimum, the most confident one is kept. The labelled trace
keeps everything of the input but its behaviour labels (replaced, with their confidences) and
fills the lane of observations that had none with the map lane the labeller found.

:func:`label_trace` also makes the user's choice for an unknown crosswalk layer (an error
without one, else its decisions counted, :func:`.rules.decide_crossings`);
:func:`label_deferred` leaves that to its caller, with the observations concerned
(:attr:`Labelling.crossing_depends`): the online labeller decides for the frames it hands out.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..model import BehaviourLabels, LabelTrace, RoadMap
from ..model.layers import UnknownLayers
from .config import LabelConfig, load_config
from .evidence import Evidence, gather
from .rules import VOCABULARY, confidences, decide_crossings
from .tracks import Tracks

LABELLER_VERSION = 3
"""Bumped whenever the labels of some input change, so that labels of an older labeller are not
reused (an ingested dataset labels its sources again). 2: lane-change sides are the vehicle's own
(swapped where it faces against its lane). 3: window sums and headings are local to their windows
(:mod:`.tracks`), which can tip a value within rounding of a threshold (the same labels on the
real traces of ../shared/real_data)."""


@dataclass(frozen=True)
class Labelling:
    """A labelled trace and, per state row, whether the object is in an intersection and whether
    its Cross confidence depends on an unknown crosswalk layer (:func:`.rules.confidences`)."""

    trace: LabelTrace
    in_intersection: np.ndarray
    crossing_depends: np.ndarray
    evidence: Evidence
    tracks: Tracks


def label_trace(
    trace: LabelTrace,
    road_map: RoadMap | None = None,
    config: LabelConfig | None = None,
    min_confidence: float | None = None,
    unknown_layers: UnknownLayers | None = None,
    interval: float | None = None,
) -> Labelling:
    """Label ``trace`` (see the module docstring); ``min_confidence`` overrides the configuration's;
    ``unknown_layers`` is the user's choice for map layers the map does not publish (see
    :mod:`.rules`: the crosswalks of the Cross rule); ``interval`` (s) pins the observation interval
    the windows are counted in (default: the median of the trace's, :class:`~.tracks.Tracks`)."""
    choice = unknown_layers or UnknownLayers()
    labelling = label_deferred(trace, road_map, config, min_confidence, choice, interval)
    decide_crossings(choice, labelling.crossing_depends, labelling.evidence.map_name)
    return labelling


def label_deferred(
    trace: LabelTrace,
    road_map: RoadMap | None = None,
    config: LabelConfig | None = None,
    min_confidence: float | None = None,
    unknown_layers: UnknownLayers | None = None,
    interval: float | None = None,
) -> Labelling:
    """:func:`label_trace` without the choice's decision: the observations whose Cross confidence
    the choice's assumption decided are :attr:`Labelling.crossing_depends`, neither counted nor
    refused (the caller does, :func:`.rules.decide_crossings`, for the rows it hands out)."""
    config = config or load_config()
    threshold = config.labels.min_confidence if min_confidence is None else min_confidence
    tracks = Tracks.of(trace, config.tracks.max_gap_s, interval)
    evidence = gather(trace, road_map, tracks, config.tracks.smooth_s)
    kinds = trace.objects.kinds()[trace.states.object[tracks.order]]
    everywhere = unknown_layers is not None and unknown_layers.everywhere
    scores, depends = confidences(evidence, kinds, tracks, config, everywhere)
    member = scores >= max(threshold, np.finfo(float).tiny)
    best = np.argmax(scores, axis=1)
    member[np.arange(len(best)), best] |= ~member.any(axis=1)
    labels = BehaviourLabels(
        VOCABULARY,
        tracks.to_rows(member),
        tracks.to_rows(np.where(member, scores, np.nan).astype(np.float32)),
    )
    labelled = replace(trace, behaviours=labels, **_with_lanes(trace, road_map, tracks.to_rows(evidence.lane)))
    rows = tracks.to_rows
    return Labelling(labelled, rows(evidence.in_intersection), rows(depends), evidence, tracks)


def _with_lanes(trace: LabelTrace, road_map: RoadMap | None, lane: np.ndarray) -> dict:
    """The states and lane vocabulary with unknown lanes filled from map lane indices."""
    fill = (trace.states.lane < 0) & (lane >= 0)
    if road_map is None or not fill.any():
        return {}
    map_ids = [lane.id for lane in road_map.lanes]
    known = set(trace.lane_ids)
    lane_ids = trace.lane_ids + tuple(map_ids[i] for i in np.unique(lane[fill]).tolist() if map_ids[i] not in known)
    code = {name: k for k, name in enumerate(lane_ids)}
    translate = np.array([code.get(name, -1) for name in map_ids], dtype=trace.states.lane.dtype)
    codes = np.where(fill, translate[np.maximum(lane, 0)], trace.states.lane)
    return {"states": replace(trace.states, lane=codes), "lane_ids": lane_ids}
