# Finds: the ego turning left while a moving vehicle drives ahead of it the same way (nuScenes "turn left, following a van")
# Run: scenario window=2s all=true unknown_layers=permissive
# Ahead: the lead is within the ego's 90-degree view (a Vehicle's viewAngle) and 30 m, faces
# within 60 degrees of the ego's heading (a lead already out of the turn is up to ~1 rad ahead of
# the ego's heading) and moves faster than 1 m/s, at every frame of the window.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior TurnLeftBehavior(), with visibleDistance 30, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
lead = new Vehicle in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always (ego can see lead)
require always (abs(relative heading of lead from ego) < 60 deg)
require always (lead.speed > 1)
