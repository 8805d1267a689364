// Reader of the 3-D points of an ASCII PLY file (the map points a SLAM run writes):
// the x, y, z properties of its "vertex" element, other elements and properties skipped.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace arucoslam {

// Throws InputError "<source>: line N: ..." for a header or data line it cannot read, a
// binary PLY, a missing vertex element or x/y/z property, and non-finite values.
std::vector<Eigen::Vector3d> ParsePlyPoints(const std::string& text, const std::string& source);
std::vector<Eigen::Vector3d> ReadPlyPoints(const std::filesystem::path& path);

}  // namespace arucoslam
