# Finds: a vehicle that stands still for the whole window, whatever the ego does (RefAV "object that hasn't moved", "stationary")
# Run: scenario window=5s unknown_layers=permissive all=true
# Scenic's own rule says it: an object without a behaviour stands still, i.e. the labeller calls it
# Stationary at every frame (its speed smoothed over 1 s under about 0.7 m/s, the 0.3-0.8 m/s ramp).
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
# Scenic's Vehicle includes bicycles (a Bicycle is a Vehicle); say Car, Truck, Bus... to leave them out.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
parked = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
