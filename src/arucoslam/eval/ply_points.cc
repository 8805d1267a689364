#include "arucoslam/eval/ply_points.h"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

struct PlyProperty {
  std::string name;
  bool is_list = false;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

std::vector<std::string> Tokens(const std::string& line) {
  std::istringstream stream(line);
  std::vector<std::string> tokens;
  std::string token;
  while (stream >> token) tokens.push_back(token);
  return tokens;
}

double ParseNumber(const std::string& token, int line_number, const std::string& source) {
  try {
    std::size_t used = 0;
    const double value = std::stod(token, &used);
    if (used == token.size() && std::isfinite(value)) return value;
  } catch (const std::logic_error&) {
  }
  throw InputError(source, fmt::format("line {}: '{}' is not a finite number", line_number, token));
}

// Reads the header up to "end_header"; `line_number` ends on that line.
std::vector<PlyElement> ParseHeader(std::istream& stream, int& line_number,
                                    const std::string& source) {
  std::string line;
  if (!std::getline(stream, line) || Tokens(line) != std::vector<std::string>{"ply"}) {
    throw InputError(source, "line 1: expected 'ply' (not a PLY file)");
  }
  line_number = 1;
  std::vector<PlyElement> elements;
  bool ascii = false;
  while (std::getline(stream, line)) {
    ++line_number;
    const std::vector<std::string> t = Tokens(line);
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") {
      if (!ascii) throw InputError(source, "no 'format ascii 1.0' line in the header");
      return elements;
    }
    if (t[0] == "format") {
      if (t.size() < 2 || t[1] != "ascii") {
        throw InputError(source,
                         fmt::format("line {}: only 'format ascii' is supported", line_number));
      }
      ascii = true;
    } else if (t[0] == "element" && t.size() == 3) {
      PlyElement element;
      element.name = t[1];
      element.count = static_cast<long long>(ParseNumber(t[2], line_number, source));
      if (element.count < 0) {
        throw InputError(source, fmt::format("line {}: negative element count", line_number));
      }
      elements.push_back(element);
    } else if (t[0] == "property" && !elements.empty() &&
               ((t.size() == 3 && t[1] != "list") || (t.size() == 5 && t[1] == "list"))) {
      elements.back().properties.push_back({t.back(), t[1] == "list"});
    } else {
      throw InputError(source,
                       fmt::format("line {}: cannot read header line '{}'", line_number, line));
    }
  }
  throw InputError(source, "no 'end_header' line");
}

}  // namespace

std::vector<Eigen::Vector3d> ParsePlyPoints(const std::string& text, const std::string& source) {
  std::istringstream stream(text);
  int line_number = 0;
  const std::vector<PlyElement> elements = ParseHeader(stream, line_number, source);
  std::vector<Eigen::Vector3d> points;
  bool found_vertex = false;
  std::string line;
  for (const PlyElement& element : elements) {
    const bool is_vertex = element.name == "vertex";
    int xyz[3] = {-1, -1, -1};
    for (std::size_t k = 0; k < element.properties.size(); ++k) {
      for (int axis = 0; axis < 3; ++axis) {
        if (!element.properties[k].is_list &&
            element.properties[k].name == std::string(1, static_cast<char>('x' + axis))) {
          xyz[axis] = static_cast<int>(k);
        }
      }
    }
    if (is_vertex) {
      found_vertex = true;
      if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) {
        throw InputError(source, "element vertex lacks an x, y or z property");
      }
    }
    for (long long row = 0; row < element.count; ++row) {
      if (!std::getline(stream, line)) {
        throw InputError(source, fmt::format("element {} ends after {} of {} lines", element.name,
                                             row, element.count));
      }
      ++line_number;
      if (!is_vertex) continue;
      const std::vector<std::string> t = Tokens(line);
      std::vector<double> values;
      std::size_t token = 0;
      for (const PlyProperty& property : element.properties) {
        if (token >= t.size()) break;
        const double value = ParseNumber(t[token++], line_number, source);
        if (property.is_list) token += static_cast<std::size_t>(std::max(value, 0.0));
        values.push_back(value);
      }
      if (values.size() != element.properties.size() || token != t.size()) {
        throw InputError(source, fmt::format("line {}: expected {} vertex properties", line_number,
                                             element.properties.size()));
      }
      points.emplace_back(values[xyz[0]], values[xyz[1]], values[xyz[2]]);
    }
  }
  if (!found_vertex) throw InputError(source, "no 'element vertex' in the header");
  return points;
}

std::vector<Eigen::Vector3d> ReadPlyPoints(const std::filesystem::path& path) {
  return ParsePlyPoints(ReadTextFile(path), path.string());
}

}  // namespace arucoslam
