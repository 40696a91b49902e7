"""Timing helpers shared by the benchmarks."""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable


def repeated_seconds(call: Callable[[], object], repeat: int) -> list[float]:
    """Wall time (s) of each of ``repeat`` calls, after one untimed warm-up call."""
    call()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return times


def median_seconds(call: Callable[[], object], repeat: int) -> float:
    """Median wall time (s) of ``repeat`` calls after one untimed warm-up call."""
    return statistics.median(repeated_seconds(call, repeat))
