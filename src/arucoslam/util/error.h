// InputError: bad user input (a file, a field, an option) detected anywhere below exe/.
// exe/ catches it and prints "arucoslam: <source>: <message>" on one line, exit status 2.
#pragma once

#include <stdexcept>
#include <string>

namespace arucoslam {

class InputError : public std::runtime_error {
 public:
  // `source` names the file (or option) at fault; `message` says what was wrong and,
  // where it helps, what was expected ("line 12: expected 8 numbers, found 7").
  InputError(std::string source, std::string message);

  const std::string& source() const { return source_; }
  const std::string& message() const { return message_; }

 private:
  std::string source_;
  std::string message_;
};

}  // namespace arucoslam
