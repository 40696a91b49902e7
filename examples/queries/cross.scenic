model scenic.simulators.newtonian.driving_model
# a pedestrian crosses while the ego does anything (without AnyBehavior, the ego must stand still)
ego = new Car with behavior AnyBehavior()
walker = new Pedestrian visible from ego, with behavior CrossBehavior()
