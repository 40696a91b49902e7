# Finds: a pedestrian at a pedestrian crossing: within 1 m of one, RefAV's distance, for the whole window (RefAV "at pedestrian crossing")
# Run: scenario window=1s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=strict all=true
# unknown_layers=strict: where a map does not publish crossings (nuScenes, CommonRoad) there is no
# crossing, so no pedestrian is at one; unknown is never "yes". A whole-box 'walker in crossing'
# would miss a pedestrian on a crossing's edge (AV2 7fab2350 de40f64f: centre 0.55 m inside).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always ((distance from walker to crossing) < 1)
