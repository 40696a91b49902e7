# A car that Scenic's Euler walk along roadDirection brings 20 to 30 m back from a random point
# on a curb (issue 15): the start is random too. On Town01 every curb point lies on a shoulder,
# so the walk's first step goes along the shoulder's centreline.
model scenic.domains.driving.model
ego = new Car on road
spot = new OrientedPoint on curb
otherCar = new Car following roadDirection from spot for Range(-30, -20)
