model scenic.domains.driving.model

# Scenario 1 of the paper's efficacy experiment (§6.1, Fig. 12):
# a pedestrian in an intersection, facing nearly perpendicular to the ego or
# toward it.
#
# Modelling choices:
# - The ego is a Car on the road, heading within 15 deg of the road direction
#   (Scenic's default would demand the exact road direction, which real labels
#   never give).
# - The pedestrian's centre is in an intersection ("in intersection"). It is not
#   required to be contained in Scenic's default walkable region (sidewalks and
#   crossings): `with regionContainedIn None`. Its heading is free (`facing
#   Range(-180, 180) deg`; otherwise "in intersection" would give it the road
#   direction).
# - "Nearly perpendicular or toward the ego": the pedestrian's heading differs
#   from the ego's by at least 70 deg (90 deg is perpendicular, 180 deg is
#   head-on toward an ego that is behind it).
# - Run with --visible-distance 50, as in the paper: any pedestrian within 50 m,
#   all around the ego (nuScenes' six cameras see all around).

ego = new Car on road, facing Range(-15, 15) deg relative to roadDirection
ped = new Pedestrian in intersection, facing Range(-180, 180) deg, with regionContainedIn None
require abs(relative heading of ped from ego) >= 70 deg
