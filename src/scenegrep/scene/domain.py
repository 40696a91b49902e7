"""The Scenic classes a scene program may instantiate, with Scenic 3.1.1's property defaults.

Defaults are written in Scenic itself (2-D compatibility mode, driving domain:
``scenic/domains/driving/model.scenic`` and ``scenic/core/object_types.py``) and
evaluated by the resolver like program text, with ``self`` the object being
built. ``kinds`` are the label kinds (:data:`scenegrep.model.taxonomy.KINDS`)
an instance may correspond to; ``None`` means any. Truck, Bus, Motorcycle and
Bicycle are not in Scenic's abstract driving domain (its simulator models add
them); they are vehicles here, so programs can name what datasets label.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache

from ..scenic import ir
from ..scenic.adapter import parse_program

VEHICLE_KINDS = frozenset({"car", "truck", "bus", "trailer", "motorcycle", "bicycle"})


@dataclass(frozen=True)
class ClassSpec:
    """A Scenic class: its parent, whether its instances are scene objects, label kinds and defaults."""

    name: str
    parent: str | None
    defaults: dict[str, str] = field(default_factory=dict)
    is_object: bool = False
    kinds: frozenset[str] | None = None


CLASSES: dict[str, ClassSpec] = {
    spec.name: spec
    for spec in (
        ClassSpec("Point", None, {"position": "(0, 0)", "visibleDistance": "50", "width": "0", "length": "0"}),
        ClassSpec("OrientedPoint", "Point", {"yaw": "0", "parentOrientation": "0", "viewAngle": "360 deg"}),
        ClassSpec(
            "Object",
            "OrientedPoint",
            {
                "width": "1",
                "length": "1",
                "regionContainedIn": "None",
                "requireVisible": "True",
                "allowCollisions": "False",
                "contactTolerance": "0",
            },
            is_object=True,
        ),
        ClassSpec("DrivingObject", "Object", {"requireVisible": "False"}, is_object=True),
        ClassSpec(
            "Vehicle",
            "DrivingObject",
            {
                "regionContainedIn": "roadOrShoulder",
                "position": "new Point on road",
                "parentOrientation": "(roadDirection at self.position) + self.roadDeviation",
                "roadDeviation": "0",
                "viewAngle": "90 deg",
                "width": "2",
                "length": "4.5",
            },
            is_object=True,
            kinds=VEHICLE_KINDS,
        ),
        ClassSpec("Car", "Vehicle", is_object=True, kinds=frozenset({"car"})),
        ClassSpec("NPCCar", "Car", is_object=True, kinds=frozenset({"car"})),
        ClassSpec("Truck", "Vehicle", {"width": "2.5", "length": "8"}, is_object=True, kinds=frozenset({"truck"})),
        ClassSpec("Bus", "Vehicle", {"width": "2.5", "length": "12"}, is_object=True, kinds=frozenset({"bus"})),
        ClassSpec(
            "Motorcycle", "Vehicle", {"width": "1", "length": "2"}, is_object=True, kinds=frozenset({"motorcycle"})
        ),
        ClassSpec("Bicycle", "Vehicle", {"width": "1", "length": "2"}, is_object=True, kinds=frozenset({"bicycle"})),
        ClassSpec(
            "Pedestrian",
            "DrivingObject",
            {
                "regionContainedIn": "network.walkableRegion",
                "position": "new Point on network.walkableRegion",
                "parentOrientation": "Range(0, 360) deg",
                "viewAngle": "90 deg",
                "width": "0.75",
                "length": "0.75",
            },
            is_object=True,
            kinds=frozenset({"pedestrian"}),
        ),
    )
}

DYNAMIC_PROPERTIES = ("speed", "velocity", "angularSpeed")
"""Scenic's dynamic properties a program may set ``with``: matched against the labels' velocities."""

DERIVED_PROPERTIES = {
    "acceleration": "acceleration is derived from the labeled velocities; compare it in a require",
}
"""scenegrep's extensions: properties Scenic 3.1.1 does not define, read from the labels (acceleration,
a vector in m/s², map frame). Setting one ``with`` is an error, so no program Scenic accepts (where
``with acceleration V`` is a user property) silently means something else here."""

NO_EFFECT_PROPERTIES = ("color", "render", "showVisibleRegion")
"""Scenic properties that only change how Scenic draws a scene: accepted, as they shape nothing."""

UNMODELLED_PROPERTIES = {
    "height": "heights are 3-D; queries are 2-D",
    "pitch": "pitch is 3-D; queries are 2-D",
    "roll": "roll is 3-D; queries are 2-D",
    "orientation": "orientation is computed from parentOrientation and yaw; set heading or yaw",
    "shape": "object shapes are boxes from the labels",
    "baseOffset": "base offsets are 3-D",
    "contactTolerance": "contact tolerances are 3-D (placement on surfaces)",
    "sideComponentThresholds": "side surfaces are 3-D",
    "onDirection": "placement on surfaces is 3-D",
    "occluding": "visibility has no occlusion in 2-D queries",
    "cameraOffset": "sensor offsets are not modelled",
    "visionSensorOffset": "sensor offsets are not modelled",
    "viewAngles": "3-D view angles are not modelled; set viewAngle",
    "viewRayCount": "ray-traced visibility is not modelled",
    "viewRayDensity": "ray-traced visibility is not modelled",
    "viewRayDistanceScaling": "ray-traced visibility is not modelled",
    "angularVelocity": "angular velocity vectors are not in the labels; angularSpeed is the 2-D one",
    "sensors": "sensors are not modelled",
    "observations": "sensor observations are not modelled",
    "lastActions": "actions are not observed in labels",
    "mutator": "mutation is not modelled",
    "mutationScale": "mutation is not modelled",
    "positionStdDev": "mutation is not modelled",
    "headingStdDev": "mutation is not modelled",
    "orientationStdDev": "mutation is not modelled",
}
"""Scenic 3.1.1 properties of Point, OrientedPoint, Object and the driving domain that shape a scene
in ways queries do not model: setting one ``with`` is an error (never silently dropped)."""

MODELS = (
    "scenic.domains.driving.model",
    "scenic.simulators.newtonian.driving_model",
    "scenic.simulators.carla.model",
    "scenic.simulators.metadrive.model",
)
"""World models a program may name: all give the driving domain's classes and map names."""


def lineage(name: str) -> list[ClassSpec]:
    """The class and its ancestors, most derived first."""
    chain = []
    spec: ClassSpec | None = CLASSES[name]
    while spec is not None:
        chain.append(spec)
        spec = CLASSES[spec.parent] if spec.parent else None
    return chain


@dataclass(frozen=True)
class Default:
    """A property default: its expression and the one-line program it was parsed from (for messages)."""

    expression: ir.Node
    program: ir.Program


@cache
def default_expression(class_name: str, prop: str) -> Default | None:
    """The default of ``prop`` for ``class_name`` (inherited), or None."""
    for spec in lineage(class_name):
        if prop in spec.defaults:
            program = parse_program(f"value = {spec.defaults[prop]}\n", f"<default {spec.name}.{prop}>")
            statement = program.statements[0]
            assert isinstance(statement, ir.Assign)
            return Default(statement.value, program)
    return None


def defaulted_properties(class_name: str) -> list[str]:
    """Every property with a default for the class, base classes' first."""
    names: list[str] = []
    for spec in reversed(lineage(class_name)):
        names.extend(p for p in spec.defaults if p not in names)
    return names
