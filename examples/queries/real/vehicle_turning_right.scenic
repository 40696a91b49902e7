# Finds: a vehicle (car, truck, bus, trailer or motorcycle) other than the ego turning right
# Run: scenario window=2s all=true unknown_layers=permissive
# TurnRight is the labeller's right turn (the heading shrinks by over ~0.44 rad over a centred 4 s);
# on maps with intersections it counts only within 3 s of one, so a right turn away from every
# intersection is not found (a car turning 8 m past one, 4 s after leaving it, is the one such miss on
# the real data). The free position, roadDeviation and regionContainedIn admit a turning vehicle
# wherever it is.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior AnyBehavior()
vehicle = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior TurnRightBehavior()
