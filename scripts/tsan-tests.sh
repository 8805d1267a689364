#!/usr/bin/env bash
# ThreadSanitizer build of the threaded tests (the System in threaded mode, local mapping and
# loop closing on their threads, the marker detector, its front-end and the ORB thread pools,
# the marker mapping published across threads, the real-time replay, the read-ahead of
# recorded frames) run clean, or fail.
# Usage: scripts/tsan-tests.sh [BUILD_DIR]   (default build-tsan; `make tsan` calls it)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build-tsan}
jobs=$(nproc)

# Test binary (path under the build folder) and the gtest filter of its threaded cases.
tests=(
  "src/arucoslam/pipeline/test_pipeline_system_test|*Threaded*:*PlaceRecognitionAlongside*"
  "src/arucoslam/pipeline/test_pipeline_system_markers_test|*Threaded*"
  "src/arucoslam/pipeline/test_pipeline_system_recovery_test|*Threaded*"
  "src/arucoslam/pipeline/test_pipeline_marker_detector_worker_test|*"
  "src/arucoslam/pipeline/test_pipeline_marker_frontend_test|*"
  "src/arucoslam/pipeline/test_pipeline_mapping_gate_test|*"
  "src/arucoslam/slam/test_slam_online_marker_mapping_test|*"
  "src/arucoslam/util/test_util_thread_pool_test|*"
  "src/arucoslam/feature/test_feature_orb_extractor_test|*ThreadCount*"
  "src/arucoslam/map/test_map_map_test|*Concurrent*"
  "src/arucoslam/io/test_io_paced_source_test|*"
  "src/arucoslam/io/test_io_read_ahead_source_test|*"
)

# -O1 keeps the instrumented tests fast enough; no ROS, no benchmarks: only what they link.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=TSan -DCMAKE_CXX_FLAGS_TSAN="-O1 -DNDEBUG" \
  -DCMAKE_CXX_FLAGS="-fsanitize=thread" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" \
  -DARUCOSLAM_ROS=OFF -DARUCOSLAM_BUILD_BENCH=OFF >/dev/null
targets=()
for entry in "${tests[@]}"; do targets+=("$(basename "${entry%%|*}")"); done
cmake --build "$build" -j"$jobs" --target "${targets[@]}"

# halt_on_error: the first race fails the test binary with exit code 66.
export TSAN_OPTIONS="halt_on_error=1 exitcode=66 second_deadlock_stack=1 suppressions=$PWD/scripts/tsan.supp"
failed=0
for entry in "${tests[@]}"; do
  binary="$build/${entry%%|*}"
  filter="${entry#*|}"
  echo "tsan: $(basename "$binary") --gtest_filter=$filter"
  if ! (cd "$(dirname "$binary")" && "./$(basename "$binary")" --gtest_filter="$filter" \
          --gtest_brief=1); then
    echo "tsan: FAILED $(basename "$binary")" >&2
    failed=1
  fi
done
exit $failed
