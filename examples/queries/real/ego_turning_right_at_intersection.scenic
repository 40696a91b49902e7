# Finds: the ego turning right inside an intersection
# Run: scenario window=2s all=true unknown_layers=permissive
# TurnRight is the labeller's (the heading shrinks by over ~0.44 rad over 4 s, near an
# intersection); the ego's centre is inside the intersection at some frame of the window.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior TurnRightBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require eventually (ego.position in intersection)
