// The protocol of the VisitOptions functions (one options_visit.h per layer): they list an
// options struct's fields once, for every reader and writer of options (io/config_file.h).
//
//   template <class Visitor> void VisitOptions(FooOptions& options, Visitor& visit) {
//     visit("key", options.key, "what it is for, units");  // one line per field
//   }
//
// The key is the C++ field's name. A field is a bool, int, std::uint32_t, double, an enum
// with an EnumNames() overload (found by argument-dependent lookup), an options struct with
// its own VisitOptions (a section), or a std::optional of one (a section that may be unset).
// Fields that are not options (data such as a marker map, callbacks) are left out, with a
// comment saying why. A comment is one line; units as DESIGN.md (metres, radians, seconds).
#pragma once

#include <string_view>

namespace arucoslam {

// One value of an enum and its name in config files and on the command line.
template <class Enum>
struct EnumName {
  Enum value;
  std::string_view name;
};

}  // namespace arucoslam
