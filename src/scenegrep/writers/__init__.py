"""Writers: the data model to files (scenegrep's Parquet and JSON trace formats, maps)."""

from .trace_json import write_trace_json
from .trace_parquet import write_map_parquet, write_trace_parquet

__all__ = ["write_map_parquet", "write_trace_json", "write_trace_parquet"]
