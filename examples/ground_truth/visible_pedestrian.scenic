# A car on the part of the road the ego sees within 30 m, and a pedestrian in view facing the ego.
# violate: pedestrian heading 0.05
# violate: car range 40
model scenic.domains.driving.model
ego = new Car on road, with visibleDistance 30
car = new Car on visible road
pedestrian = new Pedestrian visible, facing toward ego, with regionContainedIn None
