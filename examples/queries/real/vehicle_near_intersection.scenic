# Finds: frames with a moving vehicle (over 1 m/s) other than the ego whose centre is inside or within 5 m of an intersection (RefAV "near intersection")
# Run: scene unknown_layers=permissive
# A scene query, frame by frame; it reports one such vehicle per frame. "in everywhere" and the free
# roadDeviation and regionContainedIn admit vehicles off Scenic's road and across their lanes (a bus
# swinging wide at a corner). The speed is the recording's, compared exactly.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
vehicle = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require vehicle.speed > 1
require (distance from vehicle.position to intersection) < 5
