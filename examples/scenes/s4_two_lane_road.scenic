model scenic.domains.driving.model

# Scenario 4 of the paper's efficacy experiment (§6.1, Fig. 15):
# four vehicles in a typical situation on a two-lane road, two going in each
# direction.
#
# Modelling choices:
# - The ego is a Car in a lane outside intersections, heading within 15 deg of
#   the lane's direction.
# - A second Car goes the same way (heading within 15 deg of the ego's) in the
#   ego's lane: centre at most 1.5 m to either side of the ego's axis, at most
#   40 m ahead or behind.
# - Two oncoming Cars (heading 165 to 195 deg from the ego's) are in the next
#   lane to the left: centre 2 to 8 m to the left of the ego's axis, at most
#   40 m ahead or behind.
# - Offsets are measured in the ego's frame, so the road is taken as straight
#   over those 40 m. The query language has no lane adjacency or lane count
#   (and `ego.lane` is only the map's lane segment under the ego, typically
#   15-20 m long), so "two-lane road" is this lateral layout.
# - Cars are Scenic's Car: labelled class car (not trucks, buses, bikes). Their
#   boxes must lie in Scenic's default road-or-shoulder; maps without a shoulder
#   layer (nuScenes) need --unknown-layers permissive (boxes need not lie wholly
#   on the road) or strict (wholly in the lanes).
# - Run with --visible-distance 50, as in the paper.

ego = new Car on network.laneRegion, facing Range(-15, 15) deg relative to roadDirection
require (distance from ego to intersection) > 0
sameWay = new Car offset by (Range(-1.5, 1.5), Range(-40, 40)), facing Range(-15, 15) deg relative to ego.heading
oncoming1 = new Car offset by (Range(-8, -2), Range(-40, 40)), facing Range(165, 195) deg relative to ego.heading
oncoming2 = new Car offset by (Range(-8, -2), Range(-40, 40)), facing Range(165, 195) deg relative to ego.heading
