// SortIntoBuckets: indices grouped by a small integer bucket with a counting sort, for the
// extractor's cells and the quadtree's root cells (stable: index order inside each bucket).
#pragma once

#include <vector>

namespace arucoslam {

struct BucketOrder {
  std::vector<int> members;  // indices, bucket by bucket
  std::vector<int> begin;    // bucket b's members are [begin[b], begin[b + 1])
};

// bucket_of[i] in [0, num_buckets), or negative: index i is left out.
inline BucketOrder SortIntoBuckets(const std::vector<int>& bucket_of, int num_buckets) {
  BucketOrder order;
  order.begin.assign(static_cast<std::size_t>(num_buckets) + 1, 0);
  for (const int bucket : bucket_of) {
    if (bucket >= 0) ++order.begin[bucket + 1];
  }
  for (std::size_t b = 1; b < order.begin.size(); ++b) order.begin[b] += order.begin[b - 1];
  order.members.resize(order.begin.back());
  std::vector<int> next(order.begin.begin(), order.begin.end() - 1);
  for (std::size_t i = 0; i < bucket_of.size(); ++i) {
    if (bucket_of[i] >= 0) order.members[next[bucket_of[i]]++] = static_cast<int>(i);
  }
  return order;
}

}  // namespace arucoslam
