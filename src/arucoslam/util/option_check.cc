#include "arucoslam/util/option_check.h"

namespace arucoslam {

OptionCheck& OptionCheck::Require(bool passes, std::string_view field, std::string_view rule) {
  if (ok_ && !passes) Fail(field, rule, {});
  return *this;
}

void OptionCheck::Fail(std::string_view field, std::string_view rule, std::string_view value) {
  ok_ = false;
  if (why_ == nullptr) return;
  *why_ = value.empty() ? fmt::format("{} must be {}", field, rule)
                        : fmt::format("{} must be {}, is {}", field, rule, value);
}

void OptionCheck::FailNested(std::string_view field, std::string_view nested_why) {
  ok_ = false;
  if (why_ == nullptr) return;
  *why_ = nested_why.empty() ? fmt::format("{} fails its check", field)
                             : fmt::format("{}.{}", field, nested_why);
}

void OptionCheck::FailAs(std::string_view reason) {
  ok_ = false;
  if (why_ == nullptr) return;
  *why_ = reason.empty() ? std::string("the options fail their check") : std::string(reason);
}

}  // namespace arucoslam
