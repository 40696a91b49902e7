# Seed 000, 5.1 accuracy scenario 3 (Appendix 0.B.3), as a query: a pedestrian on the ego's
# lane, visible to the ego, walks along the lane. The ego follows its lane until the pedestrian
# is within 1 to 15 m, then follows it more slowly until it has passed the pedestrian.
# Simulated by examples/scenarios/s3_pass_pedestrian.scenic (Town01).
model scenic.simulators.newtonian.driving_model

behavior WalkAlongLaneBehavior(speed=1.2):
    while True:
        take SetWalkingDirectionAction(self.heading), SetWalkingSpeedAction(speed)

behavior EgoBehavior():
    try:
        do FollowLaneBehavior(target_speed=8)
    interrupt when (distance to pedestrian) < Range(1, 15):
        do FollowLaneBehavior(target_speed=3) until ((distance to pedestrian) > 5
                                                     and not (ego can see pedestrian))

ego = new Car with behavior EgoBehavior()
pedestrian = new Pedestrian on visible ego.lane, facing roadDirection, with name "pedestrian",
    with regionContainedIn None, with behavior WalkAlongLaneBehavior()
