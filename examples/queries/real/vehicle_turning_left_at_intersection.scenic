# Finds: a car other than the ego turning left inside an intersection (RefAV "passenger vehicle turning left at intersection")
# Run: scenario window=2s all=true unknown_layers=permissive
# TurnLeft is the labeller's: the heading grows by over ~0.44 rad over 4 s (centred), near an
# intersection. The car turns left through the whole 2 s window and its centre is inside the
# map's intersection at some frame of it. A turning car does not face along its lane, nor keep its
# box on the road, hence the free roadDeviation and regionContainedIn.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
car = new Car in everywhere, with behavior TurnLeftBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require eventually (car.position in intersection)
