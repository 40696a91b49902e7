# Finds: a pedestrian walking (over 0.5 m/s) between two bollards at most 3 m apart (RefAV "pedestrian crossing between bollards")
# Run: scenario window=1s tolerance_heading=0.2 tolerance_position=0.2 unknown_layers=permissive all=true
# unknown_layers=permissive: the query reads no layer a map may lack (lanes are always published);
# the choice only lets the labeller's Cross rule label nuScenes, whose crossings are unknown.
# Window 1s: passing between two posts takes about a second at walking speed.
# Tolerances: positions and headings are free here (the ego's roadDeviation, a pedestrian's
# random heading); the requirements are exact, so the tolerances only touch sizes and overlaps.
# A bollard can only be a Scenic Object (Scenic has no class for it, and Object corresponds to any
# label kind), so it is told by what can be observed: it stands still (no behaviour), is small
# (sizes under 0.7 m, within the position tolerance 0.2 m) and need not be visible from the ego.
# Cones and other small standing objects (a standing pedestrian) pass too: on the real data its one
# answer is a pedestrian between two traffic cones (nuScenes scene-0061); no recording has a
# pedestrian between bollards.
# The two 'within 3.5 m' requirements follow from the last one; they let the search drop
# far objects in one vectorised step before checking each pair.
# The pedestrian is placed anywhere ('in everywhere': Scenic's default puts it on the walkable
# region, sidewalks and crossings, which strict would shrink to the crossings alone).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
post1 = new Object in everywhere, facing Range(-180, 180) deg, with width Range(0.1, 0.7), with length Range(0.1, 0.7), with requireVisible False
post2 = new Object in everywhere, facing Range(-180, 180) deg, with width Range(0.1, 0.7), with length Range(0.1, 0.7), with requireVisible False
require always (walker.speed > 0.5)
require always ((distance from walker to post1) < 3.5)
require always ((distance from walker to post2) < 3.5)
require always ((distance from post1 to post2) < 3)
require always ((distance from walker to post1) + (distance from walker to post2) < (distance from post1 to post2) + 0.5)
