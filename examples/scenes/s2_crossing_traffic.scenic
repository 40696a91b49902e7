model scenic.domains.driving.model

# Scenario 2 of the paper's efficacy experiment (§6.1, Fig. 13):
# two vehicles in an intersection, travelling perpendicular to the ego.
#
# Modelling choices:
# - The ego is a Car on the road, heading within 15 deg of the road direction.
# - Each other vehicle is a Car (labelled class car) whose centre is in an
#   intersection, heading within 15 deg of a road direction there (a
#   direction of travel of some lane through the intersection).
# - "Perpendicular to the ego": its heading differs from the ego's by 60 to
#   120 deg, to the left or to the right.
# - Cars are Scenic's Car: labelled class car (not trucks, buses, bikes). Their
#   boxes must lie in Scenic's default road-or-shoulder; maps without a shoulder
#   layer (nuScenes) need --unknown-layers permissive (boxes need not lie wholly
#   on the road) or strict (wholly in the lanes).
# - Run with --visible-distance 50, as in the paper.

ego = new Car on road, facing Range(-15, 15) deg relative to roadDirection
car1 = new Car in intersection, facing Range(-15, 15) deg relative to roadDirection
car2 = new Car in intersection, facing Range(-15, 15) deg relative to roadDirection
require 60 deg <= abs(relative heading of car1 from ego) <= 120 deg
require 60 deg <= abs(relative heading of car2 from ego) <= 120 deg
