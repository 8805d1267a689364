#include "arucoslam/util/option_check.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace arucoslam {
namespace {

struct Inner {
  int max_iterations = 10;
  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("max_iterations", max_iterations, 1);
    return check.ok();
  }
};

struct Legacy {  // an options struct whose Check fails without writing a reason
  bool valid = true;
  bool Check(std::string* /*why*/ = nullptr) const { return valid; }
};

struct Outer {
  double ratio = 0.5;
  int low = 1;
  int high = 2;
  Inner solver;
  Legacy legacy;
  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.InRange("ratio", ratio, 0.0, 1.0, Interval::kOpen);
    check.AtLeast("high", high, low, "low");
    check.Nested("solver", solver);
    check.Nested("legacy", legacy);
    return check.ok();
  }
};

TEST(OptionCheckTest, PassesWithoutReason) {
  std::string why = "untouched";
  EXPECT_TRUE(Outer().Check(&why));
  EXPECT_EQ(why, "untouched");
  EXPECT_TRUE(Outer().Check());
}

TEST(OptionCheckTest, ComparisonsNameFieldRuleAndValue) {
  std::string why;
  EXPECT_FALSE(OptionCheck(&why).AtLeast("n", 0, 1).ok());
  EXPECT_EQ(why, "n must be >= 1, is 0");
  EXPECT_FALSE(OptionCheck(&why).Above("sigma", 0.0, 0.0).ok());
  EXPECT_EQ(why, "sigma must be > 0, is 0");
  EXPECT_FALSE(OptionCheck(&why).AtMost("n", 9, 8).ok());
  EXPECT_EQ(why, "n must be <= 8, is 9");
  EXPECT_FALSE(OptionCheck(&why).Below("margin", 0.5, 0.5).ok());
  EXPECT_EQ(why, "margin must be < 0.5, is 0.5");
  EXPECT_FALSE(OptionCheck(&why).Above("sigma", std::nan(""), 0.0).ok());
  EXPECT_TRUE(OptionCheck(nullptr).AtLeast("n", 1, 1).Below("m", 1.0, 2.0).ok());
}

TEST(OptionCheckTest, Intervals) {
  std::string why;
  EXPECT_FALSE(OptionCheck(&why).InRange("cos", 1.2, 0.0, 1.0, Interval::kOpen).ok());
  EXPECT_EQ(why, "cos must be in (0, 1), is 1.2");
  EXPECT_FALSE(OptionCheck(&why).InRange("f", -0.1, 0.0, 1.0, Interval::kClosed).ok());
  EXPECT_EQ(why, "f must be in [0, 1], is -0.1");
  EXPECT_TRUE(OptionCheck(&why).InRange("f", 1.0, 0.0, 1.0, Interval::kOpenClosed).ok());
  EXPECT_FALSE(OptionCheck(&why).InRange("f", 0.0, 0.0, 1.0, Interval::kOpenClosed).ok());
  EXPECT_TRUE(OptionCheck(&why).InRange("f", 0.0, 0.0, 1.0, Interval::kClosedOpen).ok());
  EXPECT_FALSE(OptionCheck(&why).InRange("f", 1.0, 0.0, 1.0, Interval::kClosedOpen).ok());
  EXPECT_EQ(why, "f must be in [0, 1), is 1");
  EXPECT_FALSE(OptionCheck(&why).InRange("f", std::nan(""), 0.0, 1.0, Interval::kClosed).ok());
}

TEST(OptionCheckTest, FirstFailureWinsAndBoundsCanBeNamed) {
  Outer outer;
  outer.ratio = 2.0;
  outer.high = 0;
  std::string why;
  EXPECT_FALSE(outer.Check(&why));
  EXPECT_EQ(why, "ratio must be in (0, 1), is 2");
  outer.ratio = 0.5;
  EXPECT_FALSE(outer.Check(&why));
  EXPECT_EQ(why, "high must be >= low (1), is 0");
}

TEST(OptionCheckTest, NestedReasonsArePrefixed) {
  Outer outer;
  outer.solver.max_iterations = 0;
  std::string why;
  EXPECT_FALSE(outer.Check(&why));
  EXPECT_EQ(why, "solver.max_iterations must be >= 1, is 0");
  EXPECT_FALSE(outer.Check());
  outer.solver.max_iterations = 1;
  outer.legacy.valid = false;
  EXPECT_FALSE(outer.Check(&why));
  EXPECT_EQ(why, "legacy fails its check");
}

TEST(OptionCheckTest, UnprefixedReasonsStayAsTheyAre) {
  Outer outer;
  outer.ratio = 1.5;
  std::string why;
  EXPECT_FALSE(OptionCheck(&why).Unprefixed(outer).ok());
  EXPECT_EQ(why, "ratio must be in (0, 1), is 1.5");
  outer.ratio = 0.5;
  outer.solver.max_iterations = 0;
  EXPECT_FALSE(OptionCheck(&why).Unprefixed(outer).ok());
  EXPECT_EQ(why, "solver.max_iterations must be >= 1, is 0");
  EXPECT_FALSE(OptionCheck(&why).Unprefixed(Legacy{false}).ok());
  EXPECT_EQ(why, "the options fail their check");
  EXPECT_TRUE(OptionCheck(&why).Unprefixed(Inner()).ok());
  // After a failure it is not evaluated.
  EXPECT_EQ(OptionCheck(&why).AtLeast("n", 0, 1).Unprefixed(outer).ok(), false);
  EXPECT_EQ(why, "n must be >= 1, is 0");
}

TEST(OptionCheckTest, RuleAndRequire) {
  std::string why;
  EXPECT_FALSE(OptionCheck(&why).Rule(false, "k", 3, "even").ok());
  EXPECT_EQ(why, "k must be even, is 3");
  EXPECT_FALSE(OptionCheck(&why).Require(false, "topic", "non-empty").ok());
  EXPECT_EQ(why, "topic must be non-empty");
}

}  // namespace
}  // namespace arucoslam
