"""Online scenario queries: frames arrive in chunks; a match is reported as soon as its window is complete.

The matcher keeps the last m - 1 frames (constant memory for a window of m frames).
When a chunk of k frames arrives, exactly the windows ending at those k frames are
new: the query runs on the kept frames plus the chunk, whose window starts are
those k windows, and the kept frames become the last m - 1 again.

A live input may carry its behaviour labels or not: :func:`online_results` matches labelled
chunks as they come and has the online labeller (:class:`scenegrep.label.online.OnlineLabeller`)
label the others first, its frames reaching the matcher once their labels are final.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import TYPE_CHECKING

from ..errors import UserError
from ..model import LabelTrace, RoadMap, concatenate
from .query import ScenarioOptions, ScenarioQuery, ScenarioResult, window_frames

if TYPE_CHECKING:
    from ..label.online import OnlineLabeller


class OnlineScenario:
    """Push chunks of frames (:meth:`push`); each returns the results whose windows just completed."""

    def __init__(
        self,
        query: ScenarioQuery,
        window: int | str,
        road_map: RoadMap | None = None,
        options: ScenarioOptions | None = None,
    ):
        self.query = query
        self.window = window
        self.road_map = road_map
        self.options = options
        self.kept: LabelTrace | None = None
        self.m: int | None = None

    def push(self, chunk: LabelTrace) -> list[ScenarioResult]:
        """Append ``chunk``'s frames; the result (if its window completed) of the new window starts."""
        if self.window == "all":
            raise UserError("an online query needs a window length, not 'all'")
        buffer = chunk if self.kept is None else concatenate([self.kept, chunk])
        if self.m is None:
            in_seconds = isinstance(self.window, str) and self.window.endswith("s")
            if in_seconds and buffer.n_frames < 2:  # the frame period is not known yet
                self.kept = buffer
                return []
            self.m = window_frames(self.window, buffer)
        self.kept = buffer.slice_frames(max(0, buffer.n_frames - self.m + 1), buffer.n_frames)
        if buffer.n_frames < self.m:
            return []
        result = self.query.match(buffer, self.m, self.road_map, self.options)
        return [result] if result.matched else []


def online_results(
    chunks: Iterable[LabelTrace],
    matcher: OnlineScenario,
    labeller: OnlineLabeller,
    on_delay: Callable[[str], None] = lambda delay: None,
) -> Iterator[list[ScenarioResult]]:
    """For each chunk of a live input, the results whose windows that chunk completed (often
    none); when the input ends or is stopped, :func:`final_results` gives the rest. A chunk with
    behaviour labels goes to ``matcher`` as it is, after the labeller hands out what it holds; one
    without goes through ``labeller``, and its frames reach ``matcher`` when their labels are
    final. ``on_delay`` hears the labeller's delay in words once, when it is first known. One list
    per chunk, so that a caller can time each result from its chunk's arrival."""
    for chunk in chunks:
        if chunk.behaviours is not None:
            yield final_results(matcher, labeller) + matcher.push(chunk)
            continue
        announced = labeller.delay() is not None
        labelled = labeller.push(chunk)
        if not announced and (delay := labeller.delay()) is not None:
            on_delay(delay)
        yield [] if labelled is None else matcher.push(labelled)


def final_results(matcher: OnlineScenario, labeller: OnlineLabeller) -> list[ScenarioResult]:
    """The results of the frames ``labeller`` still holds, labelled as the input ended."""
    labelled = labeller.finish()
    return [] if labelled is None else matcher.push(labelled)
