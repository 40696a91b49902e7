# Finds: a moving vehicle (over 1 m/s) other than the ego with its centre inside or within 5 m of an intersection, at each frame (RefAV "near intersection")
# Run: scenario window=2 all=true unknown_layers=permissive
# A scene, asked at every frame: the requirements hold at the first frame of a two-frame window, and
# all=true lists every vehicle at every frame. Not a scene query: a vehicle seen in a single frame
# has no speed in AV2 sensor logs (estimated from positions), an error that fails the whole log
# (7fab2350); the window needs each object at two frames, so such a track is no candidate (nor is any
# track's last frame). "in everywhere" and the free roadDeviation and regionContainedIn admit
# vehicles off Scenic's road and across their lanes (a bus swinging wide at a corner). The speed is
# the recording's (estimated from positions where a dataset records none), compared exactly.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior AnyBehavior()
vehicle = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior AnyBehavior()
require (distance from vehicle.position to intersection) < 5
require vehicle.speed > 1
