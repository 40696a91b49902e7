# Finds: a car other than the ego turning left inside an intersection (RefAV "passenger vehicle turning left at intersection")
# Run: scenario window=2s all=true unknown_layers=permissive
# TurnLeft is the labeller's left turn (the heading grows by over ~0.44 rad over a centred 4 s, within
# 3 s of an intersection): the car turns through the whole 2 s window, and its centre is inside the
# map's intersection at some frame of it. A turning car neither faces along a lane nor keeps its
# centre on Scenic's road (nuScenes lane connectors are narrow), hence "in everywhere" and the free
# roadDeviation and regionContainedIn. The ego's behaviour does not matter (AnyBehavior).
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior AnyBehavior()
car = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior TurnLeftBehavior()
require eventually (car.position in intersection)
