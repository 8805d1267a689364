#include "arucoslam/map/indexed_map.h"

#include <gtest/gtest.h>

#include <string>

#include "arucoslam/map/ids.h"

namespace arucoslam {
namespace {

using Strings = IndexedMap<MapPointId, std::string>;

TEST(IndexedMap, FindsWhatWasInsertedAndNotWhatWasErased) {
  Strings strings;
  strings.Emplace(MapPointId(3), "three");
  strings.Emplace(MapPointId(0), "zero");
  EXPECT_EQ(strings.Emplace(MapPointId(3), "again"), "three");  // the id is taken
  ASSERT_NE(strings.Find(MapPointId(3)), nullptr);
  EXPECT_EQ(*strings.Find(MapPointId(3)), "three");
  EXPECT_EQ(strings.Find(MapPointId(1)), nullptr);
  EXPECT_EQ(strings.Find(MapPointId(7)), nullptr);
  EXPECT_EQ(strings.Find(MapPointId()), nullptr);  // the invalid id
  strings.Erase(MapPointId(3));
  EXPECT_EQ(strings.Find(MapPointId(3)), nullptr);
  strings.Erase(MapPointId(5));  // absent: nothing happens
  EXPECT_EQ(strings.size(), 1u);
  EXPECT_EQ(strings.map().begin()->second, "zero");
}

TEST(IndexedMap, CopiesPointIntoTheirOwnElementsAndMovesKeepThem) {
  Strings original;
  for (int i = 0; i < 100; ++i) original.Emplace(MapPointId(i), std::to_string(i));
  original.Erase(MapPointId(40));
  Strings copy = original;
  *copy.Find(MapPointId(7)) = "changed";
  EXPECT_EQ(*original.Find(MapPointId(7)), "7");
  EXPECT_EQ(copy.Find(MapPointId(40)), nullptr);
  const std::string* element = original.Find(MapPointId(99));
  Strings moved = std::move(original);
  EXPECT_EQ(moved.Find(MapPointId(99)), element);
  EXPECT_EQ(original.Find(MapPointId(99)), nullptr);  // NOLINT(bugprone-use-after-move)
  Strings assigned;
  assigned = moved;
  EXPECT_EQ(*assigned.Find(MapPointId(98)), "98");
  EXPECT_NE(assigned.Find(MapPointId(98)), moved.Find(MapPointId(98)));
}

TEST(IndexedMap, LargeIdsAreFoundWithoutAHugeIndex) {
  Strings strings;
  const MapPointId large(std::uint64_t{1} << 40);
  strings.Emplace(large, "far");
  ASSERT_NE(strings.Find(large), nullptr);
  EXPECT_EQ(*strings.Find(large), "far");
  strings.Erase(large);
  EXPECT_EQ(strings.Find(large), nullptr);
}

TEST(IndexedMap, VisitsEveryElementInIdOrderToChangeItInPlace) {
  Strings strings;
  for (const int i : {5, 1, 3}) strings.Emplace(MapPointId(i), std::to_string(i));
  std::string order;
  strings.ForEachMutable([&](MapPointId id, std::string& element) {
    order += element;
    element += "!";
    EXPECT_EQ(strings.Find(id), &element);
  });
  EXPECT_EQ(order, "135");
  EXPECT_EQ(*strings.Find(MapPointId(3)), "3!");
  EXPECT_EQ(strings.map().rbegin()->second, "5!");
}

}  // namespace
}  // namespace arucoslam
