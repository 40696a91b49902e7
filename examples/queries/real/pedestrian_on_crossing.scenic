# Finds: a pedestrian at a pedestrian crossing: within 1 m of one, RefAV's distance, for the whole window (RefAV "at pedestrian crossing")
# Run: scenario window=1s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=strict all=true
# Window 1s: a pedestrian seen at the crossing for 1 s (10 frames at 10 Hz).
# Tolerances: positions and headings are free here (the ego's roadDeviation, a pedestrian's
# random heading); the requirements are exact, so the tolerances only touch sizes and overlaps.
# unknown_layers=strict: where a map does not publish crossings (nuScenes, CommonRoad) there is no
# crossing, so no pedestrian is at one; unknown is never "yes". A whole-box 'walker in crossing'
# would miss a pedestrian on a crossing's edge (AV2 7fab2350 de40f64f: centre 0.55 m inside).
# The pedestrian is placed anywhere ('in everywhere': Scenic's default puts it on the walkable
# region, sidewalks and crossings, which strict would shrink to the crossings alone).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always ((distance from walker to crossing) < 1)
