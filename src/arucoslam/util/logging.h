// Logging for the whole project: spdlog with one level set from the command line.
// Use ARUCOSLAM_LOG_INFO(...) etc. with fmt syntax; debug output costs nothing when off.
#pragma once

#include <spdlog/spdlog.h>

#include <string_view>

namespace arucoslam {

// Sets the global level from a name (trace, debug, info, warn, error, off).
// Returns false when the name is unknown and leaves the level unchanged.
bool SetLogLevel(std::string_view level_name);

}  // namespace arucoslam

#define ARUCOSLAM_LOG_TRACE(...) SPDLOG_TRACE(__VA_ARGS__)
#define ARUCOSLAM_LOG_DEBUG(...) ::spdlog::debug(__VA_ARGS__)
#define ARUCOSLAM_LOG_INFO(...) ::spdlog::info(__VA_ARGS__)
#define ARUCOSLAM_LOG_WARN(...) ::spdlog::warn(__VA_ARGS__)
#define ARUCOSLAM_LOG_ERROR(...) ::spdlog::error(__VA_ARGS__)
