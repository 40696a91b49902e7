"""Spatial Regular Expressions (seed 004): parse -> check -> letters -> automaton -> matches."""

from .search import CompiledQuery, Match, SearchOptions, TraceSearch, compile_query, search, search_stream

__all__ = ["CompiledQuery", "Match", "SearchOptions", "TraceSearch", "compile_query", "search", "search_stream"]
