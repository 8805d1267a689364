#include "arucoslam/markers/dictionary.h"

#include <algorithm>
#include <utility>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

using cv::aruco::PREDEFINED_DICTIONARY_NAME;

const std::vector<std::pair<std::string, PREDEFINED_DICTIONARY_NAME>>& Table() {
  static const std::vector<std::pair<std::string, PREDEFINED_DICTIONARY_NAME>> table = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
      {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
      {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
      {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
      {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
      {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
      {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
      {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
      {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
      {"DICT_APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5},
      {"DICT_APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9},
      {"DICT_APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10},
      {"DICT_APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11},
  };
  return table;
}

}  // namespace

const std::vector<std::string>& DictionaryNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> result;
    for (const auto& entry : Table()) result.push_back(entry.first);
    return result;
  }();
  return names;
}

bool IsDictionaryName(const std::string& name) {
  const auto& names = DictionaryNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

PREDEFINED_DICTIONARY_NAME DictionaryIdFromName(const std::string& name,
                                                const std::string& source) {
  for (const auto& entry : Table()) {
    if (entry.first == name) return entry.second;
  }
  std::string accepted;
  for (const auto& entry : Table()) accepted += (accepted.empty() ? "" : ", ") + entry.first;
  throw InputError(source, "unknown marker dictionary '" + name + "' (accepted: " + accepted + ")");
}

cv::Ptr<cv::aruco::Dictionary> DictionaryFromName(const std::string& name,
                                                  const std::string& source) {
  return cv::aruco::getPredefinedDictionary(DictionaryIdFromName(name, source));
}

}  // namespace arucoslam
