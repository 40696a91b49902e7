"""Spatial Regular Expressions (seed 004): parse -> check -> letters -> automaton -> matches."""

from .search import CompiledQuery, Match, SearchOptions, TraceSearch, compile_query, search, search_stream
from .vocabulary import SeenNames

__all__ = [
    "CompiledQuery",
    "Match",
    "SearchOptions",
    "SeenNames",
    "TraceSearch",
    "compile_query",
    "search",
    "search_stream",
]
