# A queue with one shared gap drawn from three options; a heading offset drawn from a normal.
# violate: middle lateral 0.05
# violate: third forward 1.5
model scenic.domains.driving.model
param weather = Options(['rain', 'clear'])
ego = new Car on road
gap = Uniform(3, 6, 9)
middle = new Car ahead of ego by gap, facing Normal(0, 1) relative to ego.heading
third = new Car ahead of middle by gap
require (relative heading of middle from ego) < 30 deg
