# Finds: the ego driving (over 2 m/s) toward a pedestrian at a pedestrian crossing (within 1 m of one), from within 30 m, the distance shrinking (RefAV "ego vehicle approaching pedestrian at crosswalk")
# Run: scenario window=2s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=strict all=true
# Window 2s: long enough that the approach is sustained, short enough for a passing pedestrian.
# Tolerances: positions and headings are free here (the ego's roadDeviation, a pedestrian's
# random heading); the requirements are exact, so the tolerances only touch sizes and overlaps.
# unknown_layers=strict: where a map does not publish crossings (nuScenes, CommonRoad) there is no
# crossing, so no pedestrian is at one; unknown is never "yes".
# "Toward": the pedestrian within 30 deg of the ego's heading. The language cannot compare a
# distance with its value at an earlier frame, so "shrinking" is made sure by speeds: the ego
# closes in at over 2 m/s x cos 30 deg = 1.73 m/s, faster than a pedestrian under 1.7 m/s can
# walk away. It misses a pedestrian going faster than 1.7 m/s whom the ego still catches up with
# (none in the data: the one approach found, AV2 7fab2350, agrees with the raw distances).
# The pedestrian is placed anywhere ('in everywhere': Scenic's default puts it on the walkable
# region, sidewalks and crossings, which strict would shrink to the crossings alone).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always ((distance from walker to crossing) < 1)
require always (ego.speed > 2)
require always ((distance from ego to walker) < 30)
require always (abs(relative heading of (angle from ego to walker) from ego.heading) < 30 deg)
require always (walker.speed < 1.7)
