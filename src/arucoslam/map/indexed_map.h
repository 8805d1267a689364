// IndexedMap: the id-ordered std::map that holds a map's keyframes or points, with a lookup by
// id in constant time. Ids come from an IdGenerator (small, dense integers), so the lookup is
// a vector of pointers to the std::map's nodes, which never move.
#pragma once

#include <cstddef>
#include <map>
#include <utility>
#include <vector>

namespace arucoslam {

template <typename Id, typename T>
class IndexedMap {
 public:
  IndexedMap() = default;
  IndexedMap(const IndexedMap& other) : map_(other.map_) { Reindex(); }
  IndexedMap& operator=(const IndexedMap& other) {
    if (this != &other) {
      map_ = other.map_;
      Reindex();
    }
    return *this;
  }
  // A moved std::map keeps its nodes, so the pointers stay valid.
  IndexedMap(IndexedMap&& other) noexcept
      : map_(std::move(other.map_)), index_(std::move(other.index_)) {
    other.map_.clear();
    other.index_.clear();
  }
  IndexedMap& operator=(IndexedMap&& other) noexcept {
    if (this != &other) {
      map_ = std::move(other.map_);
      index_ = std::move(other.index_);
      other.map_.clear();
      other.index_.clear();
    }
    return *this;
  }

  const std::map<Id, T>& map() const { return map_; }
  // Every element in id order, to be changed in place (ids stay as they are).
  template <typename Visit>
  void ForEachMutable(Visit visit) {
    for (auto& [id, element] : map_) visit(id, element);
  }
  std::size_t size() const { return map_.size(); }

  T* Find(Id id) {
    if (id.value < index_.size()) return index_[id.value];
    if (id.value < kMaxIndexed) return nullptr;
    const auto it = map_.find(id);
    return it == map_.end() ? nullptr : &it->second;
  }
  const T* Find(Id id) const { return const_cast<IndexedMap*>(this)->Find(id); }

  // Inserts `value` under `id` unless the id is taken; returns the stored element.
  T& Emplace(Id id, T value) {
    const auto [it, inserted] = map_.emplace(id, std::move(value));
    if (inserted) Index(id, &it->second);
    return it->second;
  }
  void Erase(Id id) {
    if (map_.erase(id) != 0) Index(id, nullptr);
  }

 private:
  // Ids from kMaxIndexed on (never handed out by an IdGenerator in practice) are looked up in
  // the std::map instead, so that a stray id cannot allocate a huge index.
  static constexpr std::size_t kMaxIndexed = std::size_t{1} << 26;

  void Index(Id id, T* element) {
    if (id.value >= kMaxIndexed) return;
    if (id.value >= index_.size()) {
      if (element == nullptr) return;
      index_.resize(id.value + 1, nullptr);
    }
    index_[id.value] = element;
  }
  void Reindex() {
    index_.clear();
    for (auto& [id, element] : map_) Index(id, &element);
  }

  std::map<Id, T> map_;
  std::vector<T*> index_;  // id value -> element, nullptr when absent
};

}  // namespace arucoslam
