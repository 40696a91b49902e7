# Finds: a vehicle that stands still for the whole window, whatever the ego does (RefAV "object that hasn't moved", "stationary")
# Run: scenario window=5s unknown_layers=permissive all=true
# Scenic's own rule says it: an object without a behaviour stands still, i.e. the labeller calls it
# Stationary at every frame (smoothed speed under 0.3-0.8 m/s). The free heading and region let a
# parked car stand across its lane or off the road.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
parked = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
