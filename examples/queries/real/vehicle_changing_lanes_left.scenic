# Finds: a vehicle changing lanes to the left (RefAV "vehicle changing lanes to the left")
# Run: scenario window=1s unknown_layers=permissive all=true
# The vehicle is labelled LaneChangeLeft at every frame of a 1 s window (the labeller's sustained
# sideways speed or lane-id change to the left neighbour); it may face anywhere and stand anywhere.
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
car = new Vehicle with behavior LaneChangeLeftBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
