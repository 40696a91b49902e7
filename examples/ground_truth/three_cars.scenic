# Three cars: behind, and to the left facing the one behind; headings off the road by up to 10 deg.
# violate: leftCar heading 0.05
# violate: behindCar lateral 0.05
# violate: behindCar heading 0.05
model scenic.domains.driving.model
ego = new Car on road, facing Range(-10, 10) deg relative to roadDirection
behindCar = new Car behind ego by Range(2, 5)
leftCar = new Car left of ego by Range(1, 3), facing toward behindCar
require (distance from behindCar to leftCar) < 12
