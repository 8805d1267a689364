// Map: the thread-safe owner of all keyframes and map points. Every access goes through
// Read (shared lock) or Write (exclusive lock) with a callable that receives the MapData.
#pragma once

#include <cstdint>
#include <mutex>
#include <shared_mutex>
#include <type_traits>
#include <utility>

#include "arucoslam/map/map_data.h"

namespace arucoslam {

// Usage:
//   const int n = map.Read([](const MapData& data) { return data.NumKeyframes(); });
//   map.Write([&](MapData& data) { data.AddObservation(keyframe, index, point); });
// The callable runs with the lock held: keep it short, do not call back into the same Map
// (the lock is not recursive), and copy out what you need after it returns. Long work
// (bundle adjustment) copies a snapshot in one Read and writes results in one Write.
class Map {
 public:
  Map() = default;
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  template <typename Fn>
  decltype(auto) Read(Fn&& fn) const {
    static_assert(!std::is_reference_v<std::invoke_result_t<Fn, const MapData&>>,
                  "return a copy: a reference would outlive the lock");
    std::shared_lock lock(mutex_);
    return std::forward<Fn>(fn)(static_cast<const MapData&>(data_));
  }

  template <typename Fn>
  decltype(auto) Write(Fn&& fn) {
    static_assert(!std::is_reference_v<std::invoke_result_t<Fn, MapData&>>,
                  "return a copy: a reference would outlive the lock");
    std::unique_lock lock(mutex_);
    ++version_;
    return std::forward<Fn>(fn)(data_);
  }

  // Incremented by every Write; lets a reader tell whether the map changed since a snapshot.
  std::uint64_t Version() const {
    std::shared_lock lock(mutex_);
    return version_;
  }
  std::size_t NumKeyframes() const {
    return Read([](const MapData& data) { return data.NumKeyframes(); });
  }
  std::size_t NumMapPoints() const {
    return Read([](const MapData& data) { return data.NumMapPoints(); });
  }

 private:
  mutable std::shared_mutex mutex_;
  MapData data_;
  std::uint64_t version_ = 0;
};

}  // namespace arucoslam
