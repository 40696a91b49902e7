# Finds: a vehicle changing lanes to the right while speeding up (RefAV "accelerating vehicle changing lanes to the right")
# Run: scenario window=1s unknown_layers=permissive all=true
# The vehicle is labelled LaneChangeRight at every frame of a 1 s window and its acceleration along
# its velocity is at least 0.65 m/s^2 (RefAV's `accelerating` threshold) at some frame of it. No
# position or heading tolerance is needed: the vehicle is free to face anywhere and stand anywhere.
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
car = new Vehicle with behavior LaneChangeRightBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always ((car.acceleration.x * car.velocity.x + car.acceleration.y * car.velocity.y) >= 0)
require eventually ((car.acceleration.x * car.velocity.x + car.acceleration.y * car.velocity.y) >= 0.65 * car.speed)
