#include "arucoslam/eval/ply_points.h"

#include <gtest/gtest.h>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    ParsePlyPoints(text, "map.ply");
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(PlyPoints, ReadsVerticesWithExtraPropertiesAndElements) {
  const std::string text =
      "ply\n"
      "format ascii 1.0\n"
      "comment written by a test\n"
      "element camera 1\n"
      "property float fx\n"
      "element vertex 2\n"
      "property uchar red\n"
      "property float z\n"
      "property float x\n"
      "property float y\n"
      "property list uchar int observers\n"
      "element face 1\n"
      "property list uchar int vertex_indices\n"
      "end_header\n"
      "500\n"
      "255 3.5 1 2 2 7 9\n"
      "0 -1e-2 4 5.25 0\n"
      "3 0 1 1\n";
  const std::vector<Eigen::Vector3d> points = ParsePlyPoints(text, "map.ply");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0], Eigen::Vector3d(1.0, 2.0, 3.5));
  EXPECT_EQ(points[1], Eigen::Vector3d(4.0, 5.25, -0.01));
}

TEST(PlyPoints, MalformedFilesNameTheLine) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  EXPECT_EQ(ErrorOf(header + "1 2 3\n1 2\n"), "map.ply: line 9: expected 3 vertex properties");
  EXPECT_EQ(ErrorOf(header + "1 2 3\n1 nan 3\n"), "map.ply: line 9: 'nan' is not a finite number");
  EXPECT_EQ(ErrorOf(header + "1 2 3\n"), "map.ply: element vertex ends after 1 of 2 lines");
  EXPECT_EQ(ErrorOf("solid\n"), "map.ply: line 1: expected 'ply' (not a PLY file)");
  EXPECT_EQ(ErrorOf("ply\nformat binary_little_endian 1.0\n"),
            "map.ply: line 2: only 'format ascii' is supported");
  EXPECT_EQ(ErrorOf("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n"),
            "map.ply: element vertex lacks an x, y or z property");
  EXPECT_EQ(ErrorOf("ply\nformat ascii 1.0\nelement face 0\nend_header\n"),
            "map.ply: no 'element vertex' in the header");
  EXPECT_EQ(ErrorOf("ply\nformat ascii 1.0\nbogus line\n"),
            "map.ply: line 3: cannot read header line 'bogus line'");
}

}  // namespace
}  // namespace arucoslam
