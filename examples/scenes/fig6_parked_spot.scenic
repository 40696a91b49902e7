model scenic.domains.driving.model

# The paper's Fig. 6: a spot on a curb (an intermediate variable shared by the
# two cars' positions); the ego 2-4 m right of and 5-10 m ahead of the spot in
# the curb's direction, sideCar 1-3 m (gap) left of it, heading along the curb.
# Verbatim, so it needs tolerances on real labels (see fig3_car_ahead.scenic),
# and a map with curbs (nuScenes has them, Argoverse 2 does not).

spot = new OrientedPoint on curb
ego = new Car at (spot offset by (Range(2, 4), Range(5, 10)))
sideCar = new Car left of spot by Range(1, 3)
