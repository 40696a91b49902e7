# Finds: a vehicle other than the ego moving backwards, against its own heading, for 2 s (RefAV "reversing")
# Run: scenario window=2s all=true unknown_layers=permissive
# Reverse is the labeller's: the speed along the vehicle's own heading, smoothed over 1 s, below
# about -0.48 m/s. A reversing car backs out of drives and parking bays, off its lane and road.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
vehicle = new Vehicle in everywhere, with behavior ReverseBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
