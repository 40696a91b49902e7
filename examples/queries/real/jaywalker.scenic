# Finds: a jaywalker: a pedestrian walking (over 0.5 m/s) on the road (the drivable area) and more than 1 m from any pedestrian crossing (nuScenes "jaywalker")
# Run: scenario window=2s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=permissive all=true
# Window 2s: walking on the road for 2 s, not a step off the kerb.
# Tolerances: positions and headings are free here (the ego's roadDeviation, a pedestrian's
# random heading); the requirements are exact, so the tolerances only touch sizes and overlaps.
# unknown_layers=permissive: where a map does not publish crossings (nuScenes, CommonRoad) a crossing is
# taken to be everywhere, so nobody there is outside one and the query finds no jaywalker: unknown is
# never "yes" (strict would call every pedestrian walking on a nuScenes lane a jaywalker).
# The pedestrian is placed anywhere ('in everywhere': Scenic's default puts it on the walkable
# region, sidewalks and crossings, which strict would shrink to the crossings alone).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always (walker.speed > 0.5)
require always (walker.position in road)
require always ((distance from walker to crossing) > 1)
