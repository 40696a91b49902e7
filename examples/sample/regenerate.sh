#!/bin/sh
# Regenerates the sample dataset in this directory from examples/scenarios/*.scenic with
# `scenegrep synth` (Scenic 3.1.1's Newtonian driving simulator): 6 runs x 150 steps (15 s at
# 10 Hz) of each program, base seed 0, no noise. Same Scenic version + same seeds = same traces.
# Usage: examples/sample/regenerate.sh   (with scenegrep on PATH, or SCENEGREP=/path/to/scenegrep)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
examples=$(dirname "$here")
scenegrep=${SCENEGREP:-scenegrep}

rm -f "$here"/*.parquet "$here"/manifest.json
synth() {  # PROGRAM MAP
    "$scenegrep" synth "$examples/scenarios/$1.scenic" --map "$here/$2.xodr" \
        --runs 6 --steps 150 --seed 0 -o "$here"
}
synth fig1_lane_change Town06
synth s1_lane_change_stationary_car Town06
synth s2_unprotected_left_turn Town01
synth s3_pass_pedestrian Town01
synth s4_yield_right_turn Town01
synth bg1_following_traffic Town06
synth bg2_standing_pedestrian Town01
