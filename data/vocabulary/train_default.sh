#!/bin/bash
# Rebuilds data/vocabulary/orb_k10_l5.bin, the default bag-of-words vocabulary, from images
# the project may redistribute (see README.md here). Usage: train_default.sh BUILD_DIR WORK_DIR
# (real images from $ARUCOSLAM_TEST_DATA_DIR, default ../shared/data beside the repository).
set -euo pipefail
binary="$1/bin/arucoslam"
work="$2"
data="${ARUCOSLAM_TEST_DATA_DIR:-$(cd "$(dirname "$0")/../../.." && pwd)/shared/data}"
out="$(cd "$(dirname "$0")" && pwd)/orb_k10_l5.bin"
mkdir -p "$work"
cd "$work"
# Simulator renders: five factory worlds, paths sampled at 3 Hz instead of 30 Hz.
for spec in "21 low repeat 3" "22 medium repeat 3" "23 high repeat 3" "24 high teach 2" \
            "25 medium teach 4"; do
  set -- $spec
  "$binary" world factory --seed "$1" --texture "$2" --aisles "$4" --out "world_$1"
  sed -i 's/"camera_rate_hz": 30.0/"camera_rate_hz": 3.0/' "world_$1/path.json"
  "$binary" simulate --world "world_$1/world.sdf" --path "world_$1/path.json" --out "seq_$1" \
      --run "$3" --noise-seed "$1" --quiet
done
"$binary" vocab train --k 10 --levels 5 --max-features-per-image 1000 --out "$out" --images \
    seq_21/mav0/cam0/data seq_22/mav0/cam0/data seq_23/mav0/cam0/data seq_24/mav0/cam0/data \
    seq_25/mav0/cam0/data "$data/yac_mocap_aprilgrid/cam0/data" \
    "$data/fiducials_aruco_unit/images"
