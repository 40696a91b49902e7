"""Nearest misses of a scene query that matched nothing: the smallest tolerances that admit a frame.

Matching is monotone in every tolerance: a feature passes when ``|term - label| <= t`` and box
predicates are eased by t only in the lenient direction (:mod:`.lenient_boxes`), so a wider tolerance
never rejects a correspondence a narrower one admits. The search is a bisection over the examined
frames of a trace at once, each step one run of the matcher (:func:`.match.match_trace`):

1. *Ray*: every tolerance is raised together, ``t_f = base_f + s * SCALES[f]`` (capped at
   ``CAPS[f]``), and ``s`` is bisected on a log scale up to ``RAY_CAP``; the frames still admitted at
   the smallest ``s`` are the trace's nearest, the first of them its nearest miss.
2. *Refinement*: for that frame, each tolerance in turn is bisected down towards the user's value
   with the others fixed, to a relative ``PRECISION``, and rounded to ``DIGITS`` significant
   digits (down when that still admits the frame, else up). The result admits the frame, and
   lowering any one of its values by ``SLACK`` does not (lowering a value refined later only makes
   an earlier one harder to meet).

Bounded: at most ``MissLimits.frames`` evenly spaced frames of a trace and ``MissLimits.traces``
traces are examined, each with about 15 + 20 per raised tolerance runs of the matcher.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from .tolerance import Tolerance
from .match import TraceMatches, match_trace
from ..wording import counted, plural

if TYPE_CHECKING:
    from .query import SceneResult

SCALES = {"position": 1.0, "heading": 0.1, "speed": 1.0}
"""How much of each tolerance one unit of the ray parameter adds (m, rad, m/s): 1 m per 0.1 rad per 1 m/s."""
CAPS = {"position": 20.0, "heading": math.pi, "speed": 30.0}
"""The largest tolerance a miss may need (m, rad, m/s): a heading tolerance of π admits any heading."""
UNITS = {"position": "m", "heading": "rad", "speed": "m/s"}
RAY_CAP = max(CAPS[name] / SCALES[name] for name in CAPS)
"""The ray parameter at which every tolerance reaches its cap."""
RAY_FLOOR = 1e-7
RAY_PRECISION = 1e-2
PRECISION = 1e-4
DIGITS = 4
SLACK = 2e-3
"""A reported tolerance lowered by this fraction no longer admits the frame (see the docstring)."""


@dataclass(frozen=True)
class MissLimits:
    """Bounds of the search: frames examined per trace (evenly spaced), traces examined, misses kept."""

    frames: int = 64
    traces: int = 16
    kept: int = 3


@dataclass(frozen=True)
class Shortfall:
    """One tolerance a miss needs raised: its name (a :class:`Tolerance` field), the smallest value
    found that admits the frame (``value * (1 - SLACK)`` does not), and what fails just below it:
    the features (``object.feature``) or requirements of the first group the correspondence fails."""

    name: str
    value: float
    blame: list[str]

    def option(self) -> str:
        return f"--tolerance-{self.name} {self.value:.{DIGITS}g}"

    def text(self) -> str:
        return f"{', '.join(self.blame)} off by {self.value:.{DIGITS}g} {UNITS[self.name]}"


@dataclass(frozen=True)
class NearestMiss:
    """A frame (position in the trace and frame index) that the raised tolerances admit with
    ``correspondence``; ``distance`` is the ray parameter that ranks misses (smaller is nearer).
    ``source`` is where the trace was read (a path; its name when not given), ``trace`` its name."""

    source: str
    trace: str
    position: int
    frame: int
    correspondence: dict[str, str]
    needed: list[Shortfall]
    distance: float

    def tolerance(self, base: Tolerance) -> Tolerance:
        """``base`` with the tolerances this miss needs raised."""
        return replace(base, **{s.name: s.value for s in self.needed})

    def record(self) -> dict[str, Any]:
        """The miss as a JSON-ready record."""
        return {
            "nearest_miss": True,
            "source": self.source,
            "trace": self.trace,
            "frame": self.frame,
            "correspondence": self.correspondence,
            "needed": [
                {"tolerance": s.name, "value": s.value, "unit": UNITS[s.name], "fails": s.blame} for s in self.needed
            ],
        }

    def text(self) -> str:
        """One line: where, with which correspondence, what is off and the options that admit it."""
        pairs = ", ".join(f"{name}={label}" for name, label in self.correspondence.items())
        return f"{self.trace} frame {self.frame} ({pairs}): {self.shortfalls()}"

    def shortfalls(self) -> str:
        """What is off, and the options that would admit it."""
        offs = "; ".join(s.text() for s in self.needed)
        options = " ".join(s.option() for s in self.needed)
        return f"{offs} ({options} would admit it)"


class Probe:
    """Runs of the matcher on frames of one scene result's trace at other tolerances."""

    def __init__(self, result: SceneResult):
        self.result = result

    def run(
        self, tolerance: Tolerance, frames: np.ndarray, correspondence: dict[str, str] | None = None
    ) -> TraceMatches:
        options = replace(self.result.options, tolerance=tolerance, frames=frames)
        if correspondence is not None:
            options = replace(options, correspondence=correspondence)
        result = self.result
        return match_trace(result.query.program, result.matches.groups, result.trace, result.geometry, options)

    def admitted(self, tolerance: Tolerance, frames: np.ndarray) -> np.ndarray:
        """The positions among ``frames`` that some correspondence matches at ``tolerance``."""
        return frames[self.run(tolerance, frames).matched[frames]]


def spread(frames: np.ndarray, limit: int = MissLimits.frames) -> np.ndarray:
    """At most ``limit`` of ``frames``, evenly spaced (all when there are no more)."""
    if len(frames) <= limit:
        return frames
    return frames[np.unique(np.linspace(0, len(frames) - 1, limit).round().astype(np.intp))]


def raised(base: Tolerance, s: float) -> Tolerance:
    """The ray's tolerances at parameter ``s`` (see the module docstring)."""
    return replace(
        base, **{f.name: min(getattr(base, f.name) + s * SCALES[f.name], CAPS[f.name]) for f in fields(base)}
    )


def rounded(value: float, up: bool = True) -> float:
    """The nearest number of ``DIGITS`` significant decimal digits at least (``up``) or at most
    ``value``, as the float its decimal text parses to (so a printed option is the value tested)."""
    if value <= 0:
        return value
    exponent = math.floor(math.log10(value)) - DIGITS + 1
    scaled = value / 10.0**exponent
    digits = math.ceil(scaled) if up else math.floor(scaled)
    found = float(f"{digits}e{exponent}")
    if up and found < value:
        return float(f"{digits + 1}e{exponent}")
    if not up and found > value:
        return float(f"{digits - 1}e{exponent}")
    return found


def nearest_miss(
    result: SceneResult, frames: np.ndarray, ray_cap: float = RAY_CAP, source: str | None = None
) -> NearestMiss | None:
    """The nearest miss among ``frames`` (positions) of a result, or None when raising every tolerance
    up to its cap (or the ray up to ``ray_cap``) admits none of them; ``source`` is where the
    trace was read, a path (default: the trace's name)."""
    probe = Probe(result)
    base = result.options.tolerance
    ray = _ray(probe, base, frames, ray_cap)
    if ray is None:
        return None
    s, frame = ray
    at = np.array([frame])
    tolerance = raised(base, s)
    for f in fields(base):
        tolerance = _refined(probe, base, tolerance, f.name, at)
    matches = probe.run(tolerance, at)
    correspondence = matches.correspondence[frame] or {}
    needed = [
        Shortfall(f.name, getattr(tolerance, f.name), _blame(probe, tolerance, f.name, at, correspondence))
        for f in fields(base)
        if getattr(tolerance, f.name) > getattr(base, f.name)
    ]
    index = int(result.trace.frame_index[frame])
    name = result.trace.name
    return NearestMiss(source or name, name, frame, index, correspondence, needed, s)


def _ray(probe: Probe, base: Tolerance, frames: np.ndarray, ray_cap: float) -> tuple[float, int] | None:
    """(smallest ray parameter found, the first frame it admits), or None."""
    low, high = RAY_FLOOR, ray_cap
    best = probe.admitted(raised(base, high), frames)
    if not len(best):
        return None
    while high > low * (1 + RAY_PRECISION):
        middle = math.sqrt(low * high)
        found = probe.admitted(raised(base, middle), best)
        if len(found):
            high, best = middle, found
        else:
            low = middle
    return high, int(best[0])


def _refined(probe: Probe, base: Tolerance, tolerance: Tolerance, name: str, at: np.ndarray) -> Tolerance:
    """``tolerance`` with tolerance ``name`` lowered to the smallest value (of ``DIGITS`` significant
    digits) that still admits the frame ``at``, never below the user's value in ``base``."""
    floor, value = getattr(base, name), getattr(tolerance, name)
    if value <= floor:
        return tolerance
    lowest = replace(tolerance, **{name: floor})
    if len(probe.admitted(lowest, at)):
        return lowest
    low, high = max(floor, value * 1e-9), value
    while high > low * (1 + PRECISION):
        middle = math.sqrt(low * high)
        if len(probe.admitted(replace(tolerance, **{name: middle}), at)):
            high = middle
        else:
            low = middle
    down = replace(tolerance, **{name: rounded(high, up=False)})
    if getattr(down, name) > floor and len(probe.admitted(down, at)):
        return down
    return replace(tolerance, **{name: min(rounded(high), value)})


def _blame(probe: Probe, tolerance: Tolerance, name: str, at: np.ndarray, correspondence: dict[str, str]) -> list[str]:
    """What the correspondence fails with tolerance ``name`` just below its value: the features
    compared with that tolerance in the first failing group, else the group's requirements."""
    lowered = replace(tolerance, **{name: getattr(tolerance, name) * (1 - SLACK)})
    matches = probe.run(lowered, at, correspondence)
    g = int(matches.failed_group[int(at[0])])
    if g < 0:
        return ["nothing (the frame matches just below this value)"]
    if g >= len(matches.groups):
        return ["label objects the program does not account for (exact match)"]
    group = matches.groups[g]
    features = [repr(f) for f in group.features if Tolerance.name_of(f) == name]
    return features or [r.description for r in group.requirements] or [group.describe()]


@dataclass
class NearestMisses:
    """The nearest misses over the traces of a query that matched nothing, nearest first: at most
    one per trace, ``limits.kept`` in all; traces past ``limits.traces`` are counted, not examined,
    and so are traces where the scene already holds at a frame given (a scenario's initial scene
    can hold where its behaviours fail)."""

    limits: MissLimits = field(default_factory=MissLimits)
    found: list[NearestMiss] = field(default_factory=list)
    traces: int = 0
    frames: int = 0
    skipped: int = 0
    holding: int = 0

    def add(
        self, result: SceneResult, frames: np.ndarray | None = None, source: str | None = None
    ) -> NearestMiss | None:
        """Examine a result's frames (positions; default all), at most ``limits.frames`` of them;
        ``source`` is where the trace was read, a path (default: its name)."""
        if self.traces >= self.limits.traces:
            self.skipped += 1
            return None
        self.traces += 1
        frames = np.arange(result.trace.n_frames) if frames is None else np.asarray(frames, dtype=np.intp)
        if result.matched[frames].any():
            self.holding += 1
            return None
        frames = spread(frames, self.limits.frames)
        self.frames += len(frames)
        if not len(frames):
            return None
        cap = self.found[-1].distance if len(self.found) >= self.limits.kept else RAY_CAP
        miss = nearest_miss(result, frames, cap, source)
        if miss is not None:
            self.found = sorted([*self.found, miss], key=lambda m: m.distance)[: self.limits.kept]
        return miss

    def summary(self) -> str:
        """What was examined, and the bounds."""
        text = (
            f"nearest misses searched in {counted(self.frames, 'frame')} of {counted(self.traces, 'trace')} "
            f"(at most {counted(self.limits.frames, 'frame')} per trace, {counted(self.limits.traces, 'trace')}, "
            "tolerances up to " + ", ".join(f"{name} {cap:.4g} {UNITS[name]}" for name, cap in CAPS.items()) + ")"
        )
        if self.skipped:
            text += f"; {self.skipped} more {plural('trace', self.skipped)} not examined"
        if self.holding:
            text += (
                f"; the scene holds in {self.holding} of them (a scenario's behaviours fail there: "
                "--explain says where)"
            )
        if not self.found:
            text += "; none is admitted within those tolerances"
        return text
