// StrongId: a small typed integer id, so that a FrameId cannot be passed where a MapPointId
// is expected. Default-constructed ids are invalid; ids hash and order like their values.
#pragma once

#include <compare>
#include <cstdint>
#include <functional>
#include <limits>

namespace arucoslam {

template <typename Tag, typename Value = std::uint64_t>
struct StrongId {
  using ValueType = Value;
  static constexpr Value kInvalidValue = std::numeric_limits<Value>::max();

  Value value = kInvalidValue;

  constexpr StrongId() = default;
  constexpr explicit StrongId(Value value_in) : value(value_in) {}

  constexpr bool IsValid() const { return value != kInvalidValue; }
  static constexpr StrongId Invalid() { return StrongId(); }

  friend constexpr auto operator<=>(const StrongId&, const StrongId&) = default;
};

// Hands out increasing ids of one type: 0, 1, 2, ... Not thread-safe on its own; the
// owner (e.g. Map) calls it under its lock.
template <typename IdType>
class IdGenerator {
 public:
  IdType Next() { return IdType(next_++); }
  typename IdType::ValueType Peek() const { return next_; }

 private:
  typename IdType::ValueType next_ = 0;
};

}  // namespace arucoslam

template <typename Tag, typename Value>
struct std::hash<arucoslam::StrongId<Tag, Value>> {
  std::size_t operator()(const arucoslam::StrongId<Tag, Value>& id) const noexcept {
    return std::hash<Value>{}(id.value);
  }
};
