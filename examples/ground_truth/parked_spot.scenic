# Seed 003's Fig. 6: two cars placed relative to one random spot on the curb (jointly dependent).
# violate: ego heading 0.05
# violate: sideCar range 30
model scenic.domains.driving.model
spot = new OrientedPoint on curb
ego = new Car at (spot offset by (Range(2, 4), Range(5, 10)))
sideCar = new Car left of spot by Range(1, 3)
