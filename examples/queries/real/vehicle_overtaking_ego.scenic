# Finds: a faster vehicle in a lane beside the ego's passing it from behind to ahead (nuScenes "car overtaking us")
# Run: scenario window=4s unknown_layers=permissive all=true
# At the window's first frame the vehicle is behind the ego (along its own heading, `distance past`);
# until a later frame where it is ahead, it stays 2-6 m to the side of the ego (squared lateral offset
# = distance^2 - distance past^2: a lane beside), faces the ego's way within 0.5 rad and is faster
# than the moving ego (`until`: after it is ahead, it may turn off or slow down).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
car = new Vehicle with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require (distance past ego of car) < 0
require (4 < (distance from ego to car) ** 2 - (distance past ego of car) ** 2 < 36 and abs(relative heading of car from ego) < 0.5 and car.speed > ego.speed and ego.speed > 1) until ((distance past ego of car) > 0)
