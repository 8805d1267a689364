// OptionCheck: the rules of an options struct's `bool Check(std::string* why = nullptr)
// const`, one line per rule. The first rule that fails writes one reason to *why, naming the
// field (nested sections prefixed: "solver.max_iterations") and the rule, with the value:
//
//   bool FooOptions::Check(std::string* why) const {
//     OptionCheck check(why);
//     check.AtLeast("max_iterations", max_iterations, 1);  // "max_iterations must be >= 1, is 0"
//     check.InRange("ratio", ratio, 0.0, 1.0, Interval::kOpenClosed);  // "... in (0, 1], is 2"
//     check.Nested("solver", solver);  // "solver.<solver's reason>"
//     check.Unprefixed(derived);  // "<derived's reason>": its fields are named like these
//     return check.ok();
//   }
//
// Rules after the first failure are not evaluated. Each rule's condition is the comparison
// its name says (NaN fails every rule).
#pragma once

#include <fmt/format.h>

#include <string>
#include <string_view>

namespace arucoslam {

// Which ends of an InRange interval are included: kOpen (lo, hi), kClosed [lo, hi], ...
enum class Interval { kOpen, kClosed, kOpenClosed, kClosedOpen };

class OptionCheck {
 public:
  explicit OptionCheck(std::string* why) : why_(why) {}

  bool ok() const { return ok_; }

  // value >= bound (> for Above, <= for AtMost, < for Below). A non-empty bound_name names the
  // field the bound comes from: "must be >= min_matches (8), is 5".
  template <class T, class U>
  OptionCheck& AtLeast(std::string_view field, const T& value, const U& bound,
                       std::string_view bound_name = {}) {
    return Compare(value >= bound, field, value, ">=", bound, bound_name);
  }
  template <class T, class U>
  OptionCheck& Above(std::string_view field, const T& value, const U& bound,
                     std::string_view bound_name = {}) {
    return Compare(value > bound, field, value, ">", bound, bound_name);
  }
  template <class T, class U>
  OptionCheck& AtMost(std::string_view field, const T& value, const U& bound,
                      std::string_view bound_name = {}) {
    return Compare(value <= bound, field, value, "<=", bound, bound_name);
  }
  template <class T, class U>
  OptionCheck& Below(std::string_view field, const T& value, const U& bound,
                     std::string_view bound_name = {}) {
    return Compare(value < bound, field, value, "<", bound, bound_name);
  }

  // lo < or <= value < or <= hi, as `interval` says.
  template <class T, class L, class H>
  OptionCheck& InRange(std::string_view field, const T& value, const L& lo, const H& hi,
                       Interval interval) {
    if (!ok_) return *this;
    const bool lo_closed = interval == Interval::kClosed || interval == Interval::kClosedOpen;
    const bool hi_closed = interval == Interval::kClosed || interval == Interval::kOpenClosed;
    const bool passes =
        (lo_closed ? value >= lo : value > lo) && (hi_closed ? value <= hi : value < hi);
    if (!passes) {
      Fail(field, fmt::format("in {}{}, {}{}", lo_closed ? '[' : '(', lo, hi, hi_closed ? ']' : ')'),
           fmt::format("{}", value));
    }
    return *this;
  }

  // Any other rule: `passes` is its condition, `rule` completes "<field> must be ...".
  template <class T>
  OptionCheck& Rule(bool passes, std::string_view field, const T& value, std::string_view rule) {
    if (ok_ && !passes) Fail(field, rule, fmt::format("{}", value));
    return *this;
  }
  // A rule whose value is not worth printing (a string, a set): no ", is ..." part.
  OptionCheck& Require(bool passes, std::string_view field, std::string_view rule);

  // A nested options struct: fails with its reason prefixed by "<field>.".
  template <class Options>
  OptionCheck& Nested(std::string_view field, const Options& options) {
    if (!ok_) return *this;
    std::string nested_why;
    if (!options.Check(why_ != nullptr ? &nested_why : nullptr)) FailNested(field, nested_why);
    return *this;
  }

  // Options made from these whose fields are named alike, at this level: fails with their
  // reason as it is.
  template <class Options>
  OptionCheck& Unprefixed(const Options& options) {
    if (!ok_) return *this;
    std::string reason;
    if (!options.Check(why_ != nullptr ? &reason : nullptr)) FailAs(reason);
    return *this;
  }

 private:
  template <class T, class U>
  OptionCheck& Compare(bool passes, std::string_view field, const T& value, std::string_view op,
                       const U& bound, std::string_view bound_name) {
    if (ok_ && !passes) {
      Fail(field,
           bound_name.empty() ? fmt::format("{} {}", op, bound)
                              : fmt::format("{} {} ({})", op, bound_name, bound),
           fmt::format("{}", value));
    }
    return *this;
  }
  void Fail(std::string_view field, std::string_view rule, std::string_view value);
  void FailNested(std::string_view field, std::string_view nested_why);
  void FailAs(std::string_view reason);

  std::string* why_;
  bool ok_ = true;
};

}  // namespace arucoslam
