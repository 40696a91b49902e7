# Finds: frames with a moving vehicle (over 1 m/s) whose centre is inside or within 5 m of an intersection (RefAV "near intersection")
# Run: scene unknown_layers=permissive
# A scene query: one correspondence per matching frame (scenegrep scene reports the first it
# finds), so it answers which frames have such a vehicle; the free roadDeviation and
# regionContainedIn admit vehicles turning across or standing beside their lanes.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
vehicle = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require vehicle.speed > 1
require (distance from vehicle.position to intersection) < 5
