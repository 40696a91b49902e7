# Finds: the ego turning right inside an intersection
# Run: scenario window=2s all=true unknown_layers=permissive
# TurnRight is the labeller's right turn (the heading shrinks by over ~0.44 rad over a centred 4 s,
# within 3 s of an intersection) through the whole 2 s window, and the ego's centre is inside the
# intersection at some frame of it.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior TurnRightBehavior()
require eventually (ego.position in intersection)
