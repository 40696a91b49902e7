model scenic.domains.driving.model

# Scenario 3 of the paper's efficacy experiment (§6.1, Fig. 14):
# a rare, hazardous situation: the ego drives against traffic, and another
# vehicle is visible within 10 m.
#
# Modelling choices:
# - The ego is a Car in a lane outside intersections (inside one, lanes of every
#   direction overlap, so any heading is "against" one of them), heading
#   150 to 210 deg away from the lane's direction of travel.
# - The other vehicle is a Car on the road in the ego's view (Scenic's visible
#   region of a Car: 50 m, 90 deg cone ahead), any heading, with its centre
#   within 10 m of the ego's.
# - Cars are Scenic's Car: labelled class car (not trucks, buses, bikes). Their
#   boxes must lie in Scenic's default road-or-shoulder; maps without a shoulder
#   layer (nuScenes) need --unknown-layers permissive (boxes need not lie wholly
#   on the road) or strict (wholly in the lanes).
# - Run with --visible-distance 50, as in the paper.

ego = new Car on network.laneRegion, facing Range(150, 210) deg relative to roadDirection
require (distance from ego to intersection) > 0
other = new Car on visible road, facing Range(-180, 180) deg
require (distance to other) < 10
