# Finds: the ego driving behind the same vehicle in its lane for a whole 3 s window, both moving (RefAV "following")
# Run: scenario window=3s unknown_layers=permissive all=true
# At every frame: the lead is 0-30 m ahead of the ego along the lead's heading (`distance past`),
# the ego is within 1.5 m of the lead's axis (squared lateral offset = distance^2 - distance past^2),
# the two face the same way within 0.5 rad, and both move faster than 1 m/s.
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
lead = new Vehicle with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always (0 < (distance past ego of lead) < 30)
require always ((distance from ego to lead) ** 2 - (distance past ego of lead) ** 2 < 2.25)
require always (abs(relative heading of lead from ego) < 0.5)
require always (ego.speed > 1 and lead.speed > 1)
