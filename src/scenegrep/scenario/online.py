"""Online scenario queries: frames arrive in chunks; a match is reported as soon as its window is complete.

The matcher keeps the last m - 1 frames (constant memory for a window of m frames).
When a chunk of k frames arrives, exactly the windows ending at those k frames are
new: the query runs on the kept frames plus the chunk, whose window starts are
those k windows, and the kept frames become the last m - 1 again.
"""

from __future__ import annotations

from ..errors import UserError
from ..model import LabelTrace, RoadMap, concatenate
from .query import ScenarioOptions, ScenarioQuery, ScenarioResult, window_frames


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
