model scenic.domains.driving.model

# The paper's Fig. 3: a car 4-10 m ahead of the ego (gap between the boxes),
# not in an intersection. Verbatim: Scenic's defaults give each car exactly the
# road direction and put otherCar exactly on the ego's axis, which real labels
# never reproduce, so query real data with tolerances, e.g.
#   scenegrep scene fig3_car_ahead.scenic DATA --visible-distance 50 \
#       --tolerance-position 1 --tolerance-heading 0.2618   # 1 m, 15 deg

ego = new Car on road
otherCar = new Car ahead of ego by Range(4, 10)
require not (otherCar in intersection)
