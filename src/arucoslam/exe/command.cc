#include "arucoslam/exe/command.h"

#include "arucoslam/util/error.h"

namespace arucoslam {

void ParseIdRangeInto(const std::string& text, std::vector<int>& ids) {
  // "0-9,12,20-22" -> 0..9, 12, 20..22
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string part =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (part.empty()) throw InputError("--ids", "empty entry in '" + text + "'");
    try {
      std::size_t used = 0;
      const std::size_t dash = part.find('-', 1);
      if (dash == std::string::npos) {
        const int id = std::stoi(part, &used);
        if (used != part.size() || id < 0) throw std::invalid_argument(part);
        ids.push_back(id);
      } else {
        const int first = std::stoi(part.substr(0, dash), &used);
        if (used != dash) throw std::invalid_argument(part);
        const std::string tail = part.substr(dash + 1);
        const int last = std::stoi(tail, &used);
        if (used != tail.size() || first < 0 || last < first) throw std::invalid_argument(part);
        for (int id = first; id <= last; ++id) ids.push_back(id);
      }
    } catch (const std::logic_error&) {
      throw InputError("--ids", "cannot read '" + part + "' (expected N or N-M with N <= M)");
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
}

}  // namespace arucoslam
