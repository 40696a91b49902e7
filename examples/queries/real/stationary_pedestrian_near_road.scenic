# Finds: a pedestrian standing still (under 0.2 m/s throughout the window) within 3 m of a lane (RefAV "stationary" + "near" a lane)
# Run: scenario window=2s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=permissive all=true
# unknown_layers=permissive: the query reads no layer a map may lack (lanes are always published);
# the choice only lets the labeller's Cross rule label nuScenes, whose crossings are unknown.
# Window 2s: standing for 2 s (a walker pausing for one frame is not standing).
# Tolerances: positions and headings are free here (the ego's roadDeviation, a pedestrian's
# random heading); the requirements are exact, so the tolerances only touch sizes and overlaps.
# The pedestrian is placed anywhere ('in everywhere': Scenic's default puts it on the walkable
# region, sidewalks and crossings, which strict would shrink to the crossings alone).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always (walker.speed < 0.2)
require always ((distance from walker to network.laneRegion) < 3)
