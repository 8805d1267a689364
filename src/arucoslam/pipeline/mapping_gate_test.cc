#include "arucoslam/pipeline/mapping_gate.h"

#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <thread>

namespace arucoslam {
namespace {

using std::chrono::milliseconds;

TEST(MappingGate, HoldWaitsForTheKeyframeInProgressThenKeepsTheNextOneOut) {
  MappingGate gate;
  gate.Enter();  // a keyframe is being mapped
  EXPECT_FALSE(gate.HoldRequested());
  std::future<void> hold = std::async(std::launch::async, [&] { gate.Hold(); });
  // The mapping thread sees the hold asked for (a local BA yields to it) ...
  while (!gate.HoldRequested()) std::this_thread::yield();
  // ... and the hold cannot return while the keyframe is in progress.
  EXPECT_EQ(hold.wait_for(milliseconds(100)), std::future_status::timeout);
  gate.Leave();
  hold.get();
  // Held: the next keyframe waits until the release.
  std::future<void> next = std::async(std::launch::async, [&] { gate.Enter(); });
  EXPECT_EQ(next.wait_for(milliseconds(100)), std::future_status::timeout);
  gate.Release();
  next.get();
  EXPECT_FALSE(gate.HoldRequested());
  gate.Leave();
}

TEST(MappingGate, HoldReturnsAtOnceWhenNoKeyframeIsInProgress) {
  MappingGate gate;
  gate.Enter();
  gate.Leave();
  gate.Hold();  // would never return if the finished keyframe still counted
  gate.Release();
  gate.Enter();
  gate.Leave();
}

}  // namespace
}  // namespace arucoslam
