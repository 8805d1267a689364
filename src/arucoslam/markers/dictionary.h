// ArUco dictionaries by name: every OpenCV predefined DICT_* name maps to its dictionary;
// an unknown name is an InputError that lists what is accepted.
#pragma once

#include <opencv2/aruco.hpp>

#include <string>
#include <vector>

namespace arucoslam {

// All accepted names, in OpenCV's enum order (DICT_4X4_50 ... DICT_APRILTAG_36h11).
const std::vector<std::string>& DictionaryNames();

// Throws InputError(source, ...) when `name` is not one of DictionaryNames().
cv::aruco::PREDEFINED_DICTIONARY_NAME DictionaryIdFromName(const std::string& name,
                                                           const std::string& source = "dictionary");
cv::Ptr<cv::aruco::Dictionary> DictionaryFromName(const std::string& name,
                                                  const std::string& source = "dictionary");
bool IsDictionaryName(const std::string& name);

}  // namespace arucoslam
