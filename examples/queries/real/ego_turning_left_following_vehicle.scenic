# Finds: the ego turning left while a moving vehicle drives ahead of it the same way (nuScenes "turn left, following a van")
# Run: scenario window=2s all=true unknown_layers=permissive
# Ahead: at every frame the lead is within the ego's view (a Vehicle sees 90 degrees, 45 either side
# of its heading) up to 30 m, faces within 60 degrees of the ego's heading (a lead further into the
# turn is turned further) and moves faster than 1 m/s; the speed is the recording's (estimated from
# positions where a dataset records none) and a requirement compares it exactly.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior TurnLeftBehavior(), with visibleDistance 30
lead = new Vehicle in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior AnyBehavior()
require always (ego can see lead)
require always (abs(relative heading of lead from ego) < 60 deg)
require always (lead.speed > 1)
