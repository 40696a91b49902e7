# A car at a random bearing and range from the ego (trigonometric in the unknowns).
# violate: other range 6
model scenic.domains.driving.model
ego = new Car on road
other = new Car offset along Range(-20, 20) deg by 0 @ Range(5, 10),
    facing Range(-20, 20) deg relative to roadDirection,
    with regionContainedIn None
