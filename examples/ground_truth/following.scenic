# A car following the road direction from the ego for 10 to 30 m: Scenic's Euler walk along
# roadDirection (4 to 6 steps), heading the road direction where it ends.
# violate: otherCar lateral 0.05
# violate: otherCar heading 0.05
# violate: ego heading 0.05
model scenic.domains.driving.model
ego = new Car on road
otherCar = new Car following roadDirection from ego for Range(10, 30)
