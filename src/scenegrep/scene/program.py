"""The resolved scene program: objects with their feature terms, and the requirements.

This is the "expression forest" of seed 003 §5.1 in the project's terms: each
scene object of the program (instances of Object and its subclasses) has
*features* — the label values it must reproduce — each defined by a term over
random variables and the features of other objects (:class:`Feature`); the
program's ``require`` statements and Scenic's implicit requirements are boolean
terms (:class:`Requirement`). Points and OrientedPoints are not scene objects:
their values are intermediate terms shared by the features that use them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..scenic import ir
from .terms import Term, TermFactory

TRACE = "@trace"
"""The pseudo-object whose observed features are the trace's attributes (weather, time of day ...)."""

POSITION_FEATURES = ("x", "y")
HEADING_FEATURE = "heading"
SIZE_FEATURES = ("width", "length")
SPEED_FEATURES = ("speed", "vx", "vy")
"""Features in m/s: the speed and the map-frame velocity components."""
ANGULAR_SPEED_FEATURE = "angularSpeed"


@dataclass(frozen=True, eq=False)
class Feature:
    """Feature ``name`` of program object ``obj``: its defining ``term`` must equal the label's
    value (``observed``) within the feature's tolerance; headings compare modulo 2π. Features are
    x, y, heading and, when the program sets them ``with``, width, length, speed, vx, vy (velocity)
    and angularSpeed."""

    obj: str
    name: str
    term: Term
    observed: Term
    span: ir.Span

    @property
    def is_angle(self) -> bool:
        return self.name == HEADING_FEATURE

    def __repr__(self) -> str:
        return f"{self.obj}.{self.name}"


@dataclass(frozen=True, eq=False)
class ProgramObject:
    """A scene object of the program: name (variable, ``ego``, or ``Class@line``), class, label
    kinds it may match (None: any), features in order x, y, heading[, width, length, speed,
    angularSpeed, vx, vy], the class defaults of its size (used when a label has none), and the
    behaviour call of its ``with behavior`` specifier (None: no behaviour; only scenario queries
    read it)."""

    name: str
    class_name: str
    kinds: frozenset[str] | None
    features: tuple[Feature, ...]
    default_size: dict[str, float]
    span: ir.Span
    behaviour: ir.Call | None = None

    @property
    def is_ego(self) -> bool:
        return self.name == "ego"


@dataclass(frozen=True, eq=False)
class Requirement:
    """A boolean term that must hold: a ``require`` (soft when its probability is below 1: reported,
    not enforced), an implicit requirement of Scenic (containment, visibility, no collision), or a
    global parameter's value matching the trace attribute of the same name (``parameter``; checked
    only for traces that have that attribute). ``container_of`` names the object whose containment
    in its ``regionContainedIn`` an implicit requirement states."""

    condition: Term
    description: str
    span: ir.Span
    probability: float | None = None
    implicit: bool = False
    parameter: str | None = None
    container_of: str | None = None

    @property
    def soft(self) -> bool:
        return self.probability is not None and self.probability < 1


@dataclass(eq=False)
class SceneProgram:
    """A resolved program: scene objects in creation order, requirements, global parameters
    (name -> defining term; compared with a trace attribute of the same name when present),
    the ``param map`` path if any, and the term factory that built it all."""

    program: ir.Program
    objects: list[ProgramObject] = field(default_factory=list)
    requirements: list[Requirement] = field(default_factory=list)
    params: dict[str, Term] = field(default_factory=dict)
    map_path: str | None = None
    factory: TermFactory = field(default_factory=TermFactory)

    def object(self, name: str) -> ProgramObject:
        return next(o for o in self.objects if o.name == name)
