# Finds: a vehicle other than the ego moving backwards, against its own heading, for about 2 s (RefAV "reversing")
# Run: scenario window=1.5s all=true unknown_layers=permissive
# Reverse is the labeller's: the speed along the vehicle's own heading, smoothed over 1 s, below about
# -0.48 m/s. A reversing vehicle speeds up from and slows down to a stop, so the label holds some
# 0.2-0.3 s less than the motion at each end: 1.5 s of Reverse is about 2 s of backing up (a 2 s
# window misses a truck backing up at up to 1.1 m/s for 2 s). A reversing car leaves its lane and
# road (drives, parking bays): free position, roadDeviation and regionContainedIn.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior AnyBehavior()
vehicle = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior ReverseBehavior()
