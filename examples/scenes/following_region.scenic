# A car that Scenic's Euler walk along roadDirection brings 10 to 20 m on from a random point of
# an intersection (issue 15): the start is random in a 2-D region.
model scenic.domains.driving.model
ego = new Car on road
spot = new Point on intersection
otherCar = new Car following roadDirection from spot for Range(10, 20)
