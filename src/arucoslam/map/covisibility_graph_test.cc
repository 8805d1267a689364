#include "arucoslam/map/covisibility_graph.h"

#include <gtest/gtest.h>

namespace arucoslam {
namespace {

KeyframeId K(int i) { return KeyframeId(i); }

TEST(CovisibilityGraphTest, WeightsAreSymmetricAndVanishAtZero) {
  CovisibilityGraph graph;
  for (int i = 0; i < 3; ++i) graph.AddKeyframe(K(i), i == 0 ? KeyframeId() : K(i - 1));
  graph.AddToWeight(K(0), K(1), 3);
  graph.AddToWeight(K(1), K(0), 2);
  EXPECT_EQ(graph.Weight(K(0), K(1)), 5);
  EXPECT_EQ(graph.Weight(K(1), K(0)), 5);
  graph.AddToWeight(K(0), K(1), -5);
  EXPECT_EQ(graph.Weight(K(0), K(1)), 0);
  EXPECT_TRUE(graph.Neighbours(K(0)).empty());
  EXPECT_THROW(graph.AddToWeight(K(0), K(7), 1), std::logic_error);
}

TEST(CovisibilityGraphTest, BestCovisibleOrdersByWeightThenId) {
  CovisibilityGraph graph;
  for (int i = 0; i < 5; ++i) graph.AddKeyframe(K(i));
  graph.AddToWeight(K(0), K(1), 10);
  graph.AddToWeight(K(0), K(2), 30);
  graph.AddToWeight(K(0), K(3), 10);
  graph.AddToWeight(K(0), K(4), 20);
  EXPECT_EQ(graph.BestCovisible(K(0), 3), (std::vector<KeyframeId>{K(2), K(4), K(1)}));
  EXPECT_EQ(graph.BestCovisible(K(0), 10).size(), 4u);
  EXPECT_EQ(graph.CovisibleWithMinWeight(K(0), 15), (std::vector<KeyframeId>{K(2), K(4)}));
}

TEST(CovisibilityGraphTest, SetParentRefusesCycles) {
  CovisibilityGraph graph;
  graph.AddKeyframe(K(0));
  graph.AddKeyframe(K(1), K(0));
  graph.AddKeyframe(K(2), K(1));
  EXPECT_FALSE(graph.SetParent(K(0), K(2)));  // 2 is below 0
  EXPECT_FALSE(graph.SetParent(K(1), K(1)));
  EXPECT_TRUE(graph.SetParent(K(2), K(0)));
  EXPECT_EQ(graph.Children(K(0)), (std::set<KeyframeId>{K(1), K(2)}));
  EXPECT_TRUE(graph.Children(K(1)).empty());
}

// Tree 0 -> 1 -> {2, 3, 4}; 3 and 4 share points with 2 and with 0; 4 shares nothing with
// anyone still there but 3. Erasing 1 re-parents: 2 -> 0 (weight 8 to 0), then 3 -> 2
// (weight 9 beats its 5 to 0), then 4 -> 3 (its only edge).
TEST(CovisibilityGraphTest, RemovingAKeyframeReparentsItsChildren) {
  CovisibilityGraph graph;
  graph.AddKeyframe(K(0));
  graph.AddKeyframe(K(1), K(0));
  for (int i = 2; i <= 4; ++i) graph.AddKeyframe(K(i), K(1));
  graph.AddToWeight(K(0), K(1), 50);
  graph.AddToWeight(K(1), K(2), 40);
  graph.AddToWeight(K(1), K(3), 40);
  graph.AddToWeight(K(2), K(0), 8);
  graph.AddToWeight(K(3), K(2), 9);
  graph.AddToWeight(K(3), K(0), 5);
  graph.AddToWeight(K(4), K(3), 2);
  // 5: a child of 1 with no edge at all goes to 1's parent.
  graph.AddKeyframe(K(5), K(1));

  ASSERT_TRUE(graph.RemoveKeyframe(K(1)));
  EXPECT_FALSE(graph.Contains(K(1)));
  EXPECT_EQ(graph.Parent(K(2)), K(0));
  EXPECT_EQ(graph.Parent(K(3)), K(2));
  EXPECT_EQ(graph.Parent(K(4)), K(3));
  EXPECT_EQ(graph.Parent(K(5)), K(0));
  EXPECT_EQ(graph.Children(K(0)), (std::set<KeyframeId>{K(2), K(5)}));
  EXPECT_EQ(graph.Weight(K(0), K(1)), 0);
  EXPECT_EQ(graph.Neighbours(K(0)).count(K(1)), 0u);
  // The root with children cannot go; unknown ids are refused.
  EXPECT_FALSE(graph.RemoveKeyframe(K(0)));
  EXPECT_FALSE(graph.RemoveKeyframe(K(42)));
}

}  // namespace
}  // namespace arucoslam
