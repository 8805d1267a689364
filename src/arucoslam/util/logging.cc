#include "arucoslam/util/logging.h"

#include <string>

namespace arucoslam {

bool SetLogLevel(std::string_view level_name) {
  const spdlog::level::level_enum level = spdlog::level::from_str(std::string(level_name));
  // from_str maps unknown names to "off"; accept "off" only when asked for.
  if (level == spdlog::level::off && level_name != "off") return false;
  spdlog::set_level(level);
  return true;
}

}  // namespace arucoslam
