#include "arucoslam/util/error.h"

#include <utility>

namespace arucoslam {

InputError::InputError(std::string source, std::string message)
    : std::runtime_error(source.empty() ? message : source + ": " + message),
      source_(std::move(source)),
      message_(std::move(message)) {}

}  // namespace arucoslam
