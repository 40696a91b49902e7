"""A scenario query over a live input: each match as soon as its window is complete, as results rows.

Chunks of frames (:mod:`.live`) go to the online matcher
(:class:`scenegrep.scenario.online.OnlineScenario`, which keeps the last m - 1 frames); chunks
without behaviour labels are labelled first by the online labeller
(:class:`scenegrep.label.online.OnlineLabeller`, the offline labeller's labels a fixed delay later),
as :func:`scenegrep.scenario.online.online_results` does. Each result becomes the rows of the results
table (:func:`scenegrep.dataset.queries.scenario_rows`) that a query over files gives, the trace
being the stream: ``trace_id`` and ``name`` the stream's trace name, ``source`` the input's (the
path followed, ``-`` for standard input).

The program objects whose kinds no frame of the stream has can never correspond to anything: their
warnings (:func:`scenegrep.scene.vocabulary.unknown_kinds`, as over files) are complete once the
stream has ended, since an object of a kind may appear at any later frame.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import Any

from ..model import LabelTrace, RoadMap
from ..scenario import ScenarioOptions, ScenarioQuery, ScenarioResult


class ScenarioStream:
    """A scenario ``query`` with a ``window`` (frames, or seconds as ``"5s"``) over the frames of a
    live input at ``source``, on ``road_map`` (None: the frames' own, or none), with ``options``
    (whose ``unknown_layers`` choice also counts the labeller's decisions). ``find_all`` and
    ``explain`` shape the rows as the results table's options do."""

    def __init__(
        self,
        query: ScenarioQuery,
        window: int | str,
        road_map: RoadMap | None,
        options: ScenarioOptions,
        source: str,
        find_all: bool = False,
        explain: bool = False,
    ):
        from ..label.online import OnlineLabeller
        from ..scenario.online import OnlineScenario

        self.query = query
        self.matcher = OnlineScenario(query, window, road_map, options)
        self.labeller = OnlineLabeller(road_map, unknown_layers=options.unknown_layers)
        self.source = source
        self.find_all = find_all
        self.explain = explain
        self.categories: set[str] = set()
        self.frames = 0

    def results(
        self, chunks: Iterable[LabelTrace], on_delay: Callable[[str], None] = lambda delay: None
    ) -> Iterator[list[ScenarioResult]]:
        """For each chunk, the results whose windows it completed (often none; one list per chunk, so a
        caller can time each from its chunk's arrival); ``on_delay`` hears the labeller's delay in
        words once it is known. When the input ends or is stopped, :meth:`final` gives the rest."""
        from ..scenario.online import online_results

        yield from online_results(self._seen(chunks), self.matcher, self.labeller, on_delay)

    def final(self) -> list[ScenarioResult]:
        """The results of the frames the labeller still holds, labelled as the input ended."""
        from ..scenario.online import final_results

        return final_results(self.matcher, self.labeller)

    def rows(self, result: ScenarioResult) -> list[dict[str, Any]]:
        """A result's rows of the results table (one per window with ``find_all``, else the first),
        with the stream's identity (``trace_id``, ``name``, ``source``)."""
        from ..dataset.queries import scenario_rows

        identity = {"trace_id": result.trace.name, "name": result.trace.name, "source": self.source}
        return [{**identity, **row} for row in scenario_rows(result, self.find_all, self.explain)]

    @property
    def warnings(self) -> list[str]:
        """One warning per program object whose kinds no frame read so far has (none before a frame
        was read): complete once the stream has ended."""
        from ..model.taxonomy import kind_of
        from ..scene.vocabulary import unknown_kinds

        if not self.frames:
            return []
        return unknown_kinds(self.query.scene.program.objects, {kind_of(c) for c in self.categories})

    @property
    def notes(self) -> list[str]:
        """What the online labeller declares about the labels it gave (whole-trace inputs pinned
        from the first frames, lanes forgotten over a long off-lane stretch)."""
        return list(self.labeller.warnings)

    def _seen(self, chunks: Iterable[LabelTrace]) -> Iterator[LabelTrace]:
        """``chunks``, their objects' classes gathered as they pass."""
        for chunk in chunks:
            self.categories.update(chunk.objects.category.astype(str).tolist())
            self.frames += chunk.n_frames
            yield chunk
