# Finds: frames where a vehicle is ahead of the ego in its lane, within 30 m (RefAV "in same lane" + "ahead")
# Run: scene unknown_layers=permissive
# The vehicle's centre is 0-30 m ahead of the ego's along the ego's heading (`distance past` is
# negative ahead), at most 1.75 m (half a lane) from the ego's axis (squared lateral offset =
# distance^2 - distance past^2) and it faces the ego's way within 0.5 rad: the ego's lane, straight
# ahead (a lane that bends away within 30 m is missed). No tolerance is needed: nothing is placed.
model scenic.simulators.newtonian.driving_model
ego = new Car with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
car = new Vehicle with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require -30 < (distance past car of ego) < 0
require (distance from ego to car) ** 2 - (distance past car of ego) ** 2 < 1.75 ** 2
require abs(relative heading of car from ego) < 0.5
