# Finds: a vehicle (car, truck, bus, trailer or motorcycle) other than the ego turning right
# Run: scenario window=2s all=true unknown_layers=permissive
# TurnRight is the labeller's: the heading shrinks by over ~0.44 rad over 4 s (centred); on maps
# with intersections only within 3 s of one (the labeller's rule), so a right-hand bend of the road
# far from every intersection is not a turn.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
vehicle = new Vehicle in everywhere, with behavior TurnRightBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
