# Finds: frames with two vehicles ahead of the ego in its lane, one behind the other (RefAV "two cars back from the ego" / "N vehicles ahead")
# Run: scene unknown_layers=permissive
# `first` is 0-30 m ahead of the ego along the ego's heading and `second` 0-30 m ahead of `first`
# along first's heading, each at most 1.75 m (half a lane) from the axis of the one behind it and
# facing its way within 0.5 rad (as in vehicle_in_same_lane_ahead_of_ego.scenic, chained). Nothing
# says no third vehicle stands between them: a scene query cannot say "no other object" short of
# --exact (every object in view matched).
model scenic.simulators.newtonian.driving_model
ego = new Car with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
first = new Vehicle with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
second = new Vehicle with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require -30 < (distance past first of ego) < 0
require (distance from ego to first) ** 2 - (distance past first of ego) ** 2 < 1.75 ** 2
require abs(relative heading of first from ego) < 0.5
require -30 < (distance past second of first) < 0
require (distance from first to second) ** 2 - (distance past second of first) ** 2 < 1.75 ** 2
require abs(relative heading of second from first) < 0.5
