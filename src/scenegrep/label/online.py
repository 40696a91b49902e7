"""Online labelling: the offline labeller's labels (:func:`.labeller.label_trace` on the whole
trace), frame by frame, with a bounded history and a fixed latency.

Every quantity of the labeller at an observation reads only observations of its own track
segment (:class:`~.tracks.Tracks`) within a bounded number of *positions* (observations of that
segment) before and after it. With ``h = frames(smooth_s) // 2`` (at least 1), the lookahead
in positions is ``H = max(2h + 2, h + 1 + frames(lane_change_event_s), h + frames(turn_window_s)
// 2, h + frames(turn_intersection_margin_s))``: 1 for the finite-difference velocity, ``h`` for
each centred smoothing, 1 for each central difference (acceleration from the smoothed speed,
yaw rate from the smoothed heading), plus the lane-change and turn windows over smoothed
evidence. The lookback ``B`` is the same bound (every window is centred; a lane-id change also
reads the previous position, already counted in ``h + 1``). :func:`reach` computes it.

An observation is *final* when ``H`` later positions of its segment have arrived, or its
segment is closed (a later observation of the object more than ``max_gap_s`` after it, or
``max_gap_s`` of stream time passed without one), or the input ended; a frame is final when
all its observations are (and every earlier frame is). :class:`OnlineLabeller` relabels its
kept frames at each chunk with the vectorised offline labeller and hands out the newly final
frames; it keeps, per object still unfinished, its last ``B`` positions (at most ``B * max_gap_s``
seconds). The added latency is ``H`` observations of a track: ``H`` frames when objects are
observed every frame (3.5 s at 10 Hz with the shipped thresholds and a map with intersections),
at most ``H * max_gap_s`` seconds.

The user's choice for an unknown crosswalk layer (:mod:`.rules`) is made for the observations of
the frames handed out, once each: the decisions it affected are counted as offline (the kept
history is relabelled at every chunk, but not counted again), and without a choice the error is
raised when the first frame that needs it is handed out.

Two inputs of the offline labeller are whole-trace, and are declared, not hidden:

* the observation interval the windows are counted in is the median step of the whole trace;
  online it is pinned to the median of the first frames that have one (:func:`windows` counts
  the windows in it), and :attr:`OnlineLabeller.warnings` says so whenever a later history's
  median would count some window differently (the labels can then differ from offline; this
  relies on the whole trace's median counting the windows as some kept history's median does);
* a lane-id change after an off-lane stretch reads the last lane before it (a forward fill over
  the segment); a stretch longer than the kept history loses it, which is declared likewise.

Equality is exact otherwise: every value of the labeller at an observation reads only the
observations of its windows, summed in an order fixed by the window, and headings are never
unwrapped into running sums (:mod:`.tracks`), so an observation handed out gets the offline
confidences bit for bit and the offline label set, ties at the thresholds included (a confidence
exactly at the minimum, a speed at a ramp's end, a heading exactly perpendicular to its lane).
The property test in tests/label/test_online.py checks it on random traces that move exactly on
those boundaries.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model import LabelTrace, RoadMap, concatenate
from ..model.layers import UnknownLayers
from .config import LabelConfig, load_config
from .labeller import label_deferred
from .rules import decide_crossings
from .tracks import Tracks


def windows(config: LabelConfig, tracks: Tracks, knows_intersections: bool = True) -> tuple[int, ...]:
    """The window lengths (positions) the labeller reads at ``tracks.interval``: the smoothing's
    half window, the lane-change window, the turn's half window and, on a map with
    intersections (``knows_intersections``), the turn's intersection margin."""
    vehicle = config.vehicle
    lengths = (
        max(1, tracks.frames(config.tracks.smooth_s) // 2),
        max(1, tracks.frames(vehicle.lane_change_event_s)),
        max(1, tracks.frames(vehicle.turn_window_s) // 2),
    )
    return (*lengths, max(1, tracks.frames(vehicle.turn_intersection_margin_s))) if knows_intersections else lengths


def reach(config: LabelConfig, tracks: Tracks, knows_intersections: bool = True) -> int:
    """``H`` (= ``B``): positions of a segment the labels at one observation read on either side
    (see the module docstring); ``knows_intersections`` adds the turn's intersection margin."""
    half, *others = windows(config, tracks, knows_intersections)
    return max(2 * half + 2, half + 1 + others[0], *(half + other for other in others[1:]))


@dataclass
class OnlineLabeller:
    """Push unlabelled chunks of frames (:meth:`push`), then :meth:`finish`; each returns the
    labelled trace of the frames that became final (None when none did)."""

    road_map: RoadMap | None = None
    config: LabelConfig = field(default_factory=load_config)
    min_confidence: float | None = None
    unknown_layers: UnknownLayers | None = None
    interval: float | None = None
    warnings: list[str] = field(default_factory=list)
    kept: LabelTrace | None = None
    done: int = 0
    depth: int | None = None

    def delay(self) -> str | None:
        """The added latency in words, once the observation interval is known (else None)."""
        if self.depth is None or self.interval is None:
            return None
        return (
            f"online labels are final {self.depth} observations of a track later "
            f"({self.depth * self.interval:.1f} s at {self.interval:.3f} s per observation; "
            f"at most {self.depth * self.config.tracks.max_gap_s:.1f} s)"
        )

    def push(self, chunk: LabelTrace) -> LabelTrace | None:
        """Append ``chunk`` (frames after the kept ones); the newly final frames, labelled."""
        self.kept = chunk if self.kept is None else concatenate([self.kept, chunk])
        return self._emit(ended=False)

    def finish(self) -> LabelTrace | None:
        """The input ended: every frame not yet handed out, labelled."""
        return None if self.kept is None else self._emit(ended=True)

    def _emit(self, ended: bool) -> LabelTrace | None:
        trace = self.kept
        assert trace is not None
        gap = self.config.tracks.max_gap_s
        own = Tracks.of(trace, gap)
        if self.interval is None and len(own) > len(np.unique(own.start)):
            self.interval = own.interval
        choice = self.unknown_layers or UnknownLayers()
        labelling = label_deferred(trace, self.road_map, self.config, self.min_confidence, choice, self.interval)
        tracks = labelling.tracks
        depth = reach(self.config, tracks, labelling.evidence.knows_intersections)
        if self.interval is not None:
            self.depth = depth
        self._check_interval(own, tracks, labelling.evidence.knows_intersections)
        frame = trace.states.frame[tracks.order]
        position = np.arange(len(tracks))
        if ended:
            final = np.ones(len(tracks), dtype=bool)
        else:
            last = tracks.end - 1
            obj = trace.states.object[tracks.order]
            broken = (tracks.end < len(tracks)) & (obj[np.minimum(tracks.end, len(tracks) - 1)] == obj)
            now = trace.frame_time[-1]
            closed = broken | (now - tracks.time[last] >= gap)
            final = closed | (last - position >= depth)
        waiting = np.bincount(frame[~final], minlength=trace.n_frames) > 0
        stop = int(np.argmax(waiting)) if waiting.any() else trace.n_frames
        out = labelling.trace.slice_frames(self.done, stop) if stop > self.done else None
        handed = (trace.states.frame >= self.done) & (trace.states.frame < stop)
        decide_crossings(choice, labelling.crossing_depends[handed], labelling.evidence.map_name)
        begin = stop
        pending = frame >= stop
        if pending.any():
            back = np.maximum(position[pending] - depth, tracks.start[pending])
            begin = min(stop, int(frame[back].min()))
        self._check_lanes(trace, labelling.evidence.lane, tracks, begin)
        self.kept = None if ended else trace.slice_frames(begin, trace.n_frames)
        self.done = stop - begin
        return out

    def _check_interval(self, own: Tracks, tracks: Tracks, knows: bool) -> None:
        """Declare a history whose own median interval would count the windows differently."""
        if len(own) == len(np.unique(own.start)) or windows(self.config, own, knows) == windows(
            self.config, tracks, knows
        ):
            return
        message = (
            f"online labels: the observation interval changed from {tracks.interval:.3f} s to "
            f"{own.interval:.3f} s; labels from here on may differ from offline labelling"
        )
        if message not in self.warnings:
            self.warnings.append(message)

    def _check_lanes(self, trace: LabelTrace, lane: np.ndarray, tracks: Tracks, begin: int) -> None:
        """Declare a segment cut at frame ``begin`` (the new history's start) right before an
        off-lane observation while it had a lane before: the lane-id change at the end of that
        off-lane stretch reads the forgotten lane offline (a forward fill over the segment)."""
        frame = trace.states.frame[tracks.order]
        cut = np.flatnonzero((frame[:-1] < begin) & (frame[1:] >= begin) & (tracks.start[1:] == tracks.start[:-1]))
        filled = tracks.forward_fill(lane)
        lost = cut[(lane[cut + 1] < 0) & (filled[cut] >= 0)]
        ids = trace.objects.id[trace.states.object[tracks.order[lost]]]
        for name in ids.tolist():
            message = (
                f"online labels: object {name} is off-lane longer than the kept history; a lane "
                "change right after it may differ from offline labelling"
            )
            if message not in self.warnings:
                self.warnings.append(message)
