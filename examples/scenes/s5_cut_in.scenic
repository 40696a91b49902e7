model scenic.domains.driving.model

# Scenario 5 of the paper's efficacy experiment (§6.1, Fig. 16):
# a cut-in: a car in the adjacent lane to the right is ahead of the ego and
# angled toward the ego's lane.
#
# Modelling choices:
# - The ego is a Car in a lane, heading within 15 deg of the road direction.
# - The cut-in Car's centre is 2.5 to 5 m to the ego's right (one lane over)
#   and 0 to 15 m ahead, measured in the ego's frame ("offset by").
# - "Angled toward the ego's lane": its heading is turned 10 to 45 deg to the
#   left (toward the ego, counter-clockwise) of the ego's heading.
# - Its centre is not in the ego's lane (`ego.lane`: the map's lane segments
#   containing the ego's centre).
# - Cars are Scenic's Car: labelled class car (not trucks, buses, bikes). Their
#   boxes must lie in Scenic's default road-or-shoulder; maps without a shoulder
#   layer (nuScenes) need --unknown-layers permissive (boxes need not lie wholly
#   on the road) or strict (wholly in the lanes).
# - Run with --visible-distance 50, as in the paper.

ego = new Car on network.laneRegion, facing Range(-15, 15) deg relative to roadDirection
cutIn = new Car offset by (Range(2.5, 5), Range(0, 15)), facing Range(10, 45) deg relative to ego.heading
require not (cutIn.position in ego.lane)
