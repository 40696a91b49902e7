# Finds: a vehicle the ego follows while another vehicle passes it on its right (RefAV "vehicle being followed by ego while being overtaken on right")
# Run: scenario window=4s unknown_layers=permissive all=true
# The ego follows `lead` over the whole window as in ego_following_vehicle.scenic; `passer` starts
# behind the lead and, until a later frame where it is ahead of it, stays 2-6 m to its side on its
# right (apparent heading of passer from lead in (0, pi): clockwise of the lead's heading), facing
# its way.
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
lead = new Vehicle with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
passer = new Vehicle with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always (0 < (distance past ego of lead) < 30)
require always ((distance from ego to lead) ** 2 - (distance past ego of lead) ** 2 < 2.25)
require always (abs(relative heading of lead from ego) < 0.5)
require always (ego.speed > 1 and lead.speed > 1)
require (distance past lead of passer) < 0
require (4 < (distance from lead to passer) ** 2 - (distance past lead of passer) ** 2 < 36 and 0 < (apparent heading of passer from lead) and abs(relative heading of passer from lead) < 0.5) until ((distance past lead of passer) > 0)
