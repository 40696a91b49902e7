"""Scenic scenario queries (seed 000): windows of a label trace a program's behaviours can produce.

Pipeline: :mod:`scenegrep.scenic` (parse -> IR) -> :mod:`.translate` (behaviours -> HFSMs,
:mod:`.hfsm`; conditions -> guards) -> :mod:`.automaton` (ValidStep as a lazy DFA) ->
:mod:`.windows` (all sliding windows at once) -> :mod:`.search` (correspondences) ->
:mod:`.query` (the API) and :mod:`.explain`.
"""

from .query import (
    ScenarioMatch,
    ScenarioOptions,
    ScenarioQuery,
    ScenarioResult,
    compile_scenario,
    load_scenario,
    window_frames,
)
from .vocabulary import DEFAULT_VOCABULARY, Vocabulary, load_vocabulary

__all__ = [
    "DEFAULT_VOCABULARY",
    "ScenarioMatch",
    "ScenarioOptions",
    "ScenarioQuery",
    "ScenarioResult",
    "Vocabulary",
    "compile_scenario",
    "load_scenario",
    "load_vocabulary",
    "window_frames",
]
