# Seed 003's Fig. 3: a car 4 to 10 m ahead of the ego, not in an intersection.
# violate: otherCar lateral 0.05
# violate: otherCar heading 0.05
# violate: ego heading 0.05
# violate: otherCar forward 20
model scenic.domains.driving.model
ego = new Car on road
otherCar = new Car ahead of ego by Range(4, 10)
require not (otherCar in intersection)
