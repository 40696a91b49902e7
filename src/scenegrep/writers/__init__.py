"""Writers: the data model to files (scenegrep's Parquet and JSON trace formats, maps).

Each writer is imported on first use (``from scenegrep.writers import write_trace_parquet``
loads pyarrow, the JSON writer does not), so the readers can share a format's constants with
its writer (:data:`.strem_json.STREM_VERSION`) without loading every writer's library.
"""

from __future__ import annotations

import importlib
from typing import Any

_MODULES = {
    "write_map_parquet": "trace_parquet",
    "write_trace_json": "trace_json",
    "write_trace_parquet": "trace_parquet",
}
"""Each writer function -> the module of this package that defines it."""

__all__ = sorted(_MODULES)


def __getattr__(name: str) -> Any:
    """``write_trace_json``, ``write_trace_parquet`` and ``write_map_parquet`` from their modules."""
    if name not in _MODULES:
        raise AttributeError(f"module 'scenegrep.writers' has no attribute {name!r}")
    return getattr(importlib.import_module(f".{_MODULES[name]}", __name__), name)
