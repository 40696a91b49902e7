# Finds: a pedestrian walking (over 0.5 m/s) within 15 m of the ego while the ego drives (over 2 m/s)
# Run: scenario window=2s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=permissive all=true
# unknown_layers=permissive: the query reads no layer a map may lack (lanes are always published);
# the choice only lets the labeller's Cross rule label nuScenes, whose crossings are unknown.
# Window 2s: both moving for 2 s.
# Tolerances: positions and headings are free here (the ego's roadDeviation, a pedestrian's
# random heading); the requirements are exact, so the tolerances only touch sizes and overlaps.
# The pedestrian is placed anywhere ('in everywhere': Scenic's default puts it on the walkable
# region, sidewalks and crossings, which strict would shrink to the crossings alone).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always (ego.speed > 2)
require always (walker.speed > 0.5)
require always ((distance from ego to walker) < 15)
