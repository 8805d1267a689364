#include "arucoslam/markers/sdf_export.h"

#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

std::string Number(double value) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value == 0.0 ? 0.0 : value);  // no "-0"
  return buffer;
}

std::string XmlEscaped(const std::string& text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&apos;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

// One <visual> or <collision> element holding the marker box.
void AppendBoxElement(std::ostringstream& out, const std::string& kind, const std::string& name,
                      const std::string& pose, const std::string& size,
                      const std::string& material) {
  out << "      <" << kind << " name=\"" << name << "\">\n"
      << "        <pose>" << pose << "</pose>\n"
      << "        <geometry><box><size>" << size << "</size></box></geometry>\n"
      << material << "      </" << kind << ">\n";
}

}  // namespace

std::string MarkerModelName(int id) { return "marker_" + std::to_string(id); }

std::string MarkerTextureFileName(int id) { return MarkerModelName(id) + ".png"; }

double MarkerBoxSide(double marker_size, const std::string& dictionary,
                     const MarkerImageOptions& image) {
  const int margin = QuietZonePixels(dictionary, image);
  return marker_size * (image.marker_size_px + 2.0 * margin) / image.marker_size_px;
}

Eigen::Vector3d RollPitchYaw(const Eigen::Quaterniond& rotation) {
  const Eigen::Matrix3d r = rotation.normalized().toRotationMatrix();
  const double cos_pitch = std::hypot(r(0, 0), r(1, 0));
  const double pitch = std::atan2(-r(2, 0), cos_pitch);
  if (cos_pitch < 1e-12) {
    // Gimbal lock: only roll - yaw (or roll + yaw) is defined; put it all in roll.
    return Eigen::Vector3d(std::atan2(-r(1, 2), r(1, 1)), pitch, 0.0);
  }
  return Eigen::Vector3d(std::atan2(r(2, 1), r(2, 2)), pitch, std::atan2(r(1, 0), r(0, 0)));
}

std::string SdfPoseText(const Rigid3& parent_from_child) {
  const Eigen::Vector3d& t = parent_from_child.translation;
  const Eigen::Vector3d rpy = RollPitchYaw(parent_from_child.rotation);
  return Number(t.x()) + " " + Number(t.y()) + " " + Number(t.z()) + " " + Number(rpy.x()) + " " +
         Number(rpy.y()) + " " + Number(rpy.z());
}

std::string MarkerModelSdf(const MarkerInfo& marker, const MarkerModelSdfOptions& options) {
  const std::string source = "marker " + std::to_string(marker.id);
  if (!options.Check()) {
    throw InputError(source, "invalid SDF options (image at least 16 px, thickness > 0)");
  }
  if (!(marker.size > 0.0) || !std::isfinite(marker.size)) {
    throw InputError(source, "size must be a positive number of metres");
  }
  const double side = MarkerBoxSide(marker.size, options.dictionary, options.image);
  const std::string name =
      options.model_name.empty() ? MarkerModelName(marker.id) : options.model_name;
  const std::string texture =
      options.albedo_map.empty() ? MarkerTextureFileName(marker.id) : options.albedo_map;
  const std::string size = Number(side) + " " + Number(side) + " " + Number(options.thickness);
  // The printed face (+z of the box) lies in the marker plane z = 0.
  const std::string box_pose = "0 0 " + Number(-0.5 * options.thickness) + " 0 0 0";
  const std::string material =
      "        <material>\n"
      "          <ambient>1 1 1 1</ambient>\n"
      "          <diffuse>1 1 1 1</diffuse>\n"
      "          <pbr><metal><albedo_map>" +
      XmlEscaped(texture) +
      "</albedo_map></metal></pbr>\n"
      "        </material>\n";
  std::ostringstream out;
  out << "  <model name=\"" << XmlEscaped(name) << "\">\n"
      << "    <static>true</static>\n"
      << "    <pose>" << SdfPoseText(marker.world_from_marker) << "</pose>\n"
      << "    <link name=\"link\">\n"
      << "      <pose>0 0 0 0 0 0</pose>\n";
  AppendBoxElement(out, "visual", "visual", box_pose, size, material);
  AppendBoxElement(out, "collision", "collision", box_pose, size, "");
  out << "    </link>\n"
      << "  </model>\n";
  return out.str();
}

std::string SdfDocument(const std::string& elements) {
  return "<?xml version=\"1.0\"?>\n<sdf version=\"1.9\">\n" + elements + "</sdf>\n";
}

std::string ModelConfigText(const std::string& model_name, const std::string& description) {
  return "<?xml version=\"1.0\"?>\n"
         "<model>\n"
         "  <name>" +
         XmlEscaped(model_name) +
         "</name>\n"
         "  <version>1.0</version>\n"
         "  <sdf version=\"1.9\">model.sdf</sdf>\n"
         "  <description>" +
         XmlEscaped(description) +
         "</description>\n"
         "</model>\n";
}

std::string WorldWithIncludesSdf(const std::string& world_name,
                                 const std::vector<std::string>& model_uris) {
  std::ostringstream out;
  out << "  <!-- Model folders are found through GZ_SIM_RESOURCE_PATH (or SDF_PATH). -->\n"
      << "  <world name=\"" << XmlEscaped(world_name) << "\">\n";
  for (const std::string& uri : model_uris) {
    out << "    <include><uri>" << XmlEscaped(uri) << "</uri></include>\n";
  }
  out << "  </world>\n";
  return out.str();
}

std::filesystem::path WriteMarkerSdfFolder(const MarkerMap& map,
                                           const std::filesystem::path& folder,
                                           const MarkerImageOptions& image, double thickness) {
  MarkerModelSdfOptions options;
  options.dictionary = map.dictionary;
  options.image = image;
  options.thickness = thickness;
  std::vector<std::string> uris;
  for (const auto& [id, marker] : map.markers) {
    const std::string name = MarkerModelName(id);
    const std::filesystem::path model_folder = folder / name;
    std::filesystem::create_directories(model_folder);
    const std::filesystem::path png = model_folder / MarkerTextureFileName(id);
    if (!cv::imwrite(png.string(), DrawMarkerImage(map.dictionary, id, image))) {
      throw InputError(png.string(), "cannot write the marker image");
    }
    WriteTextFileAtomically(model_folder / "model.sdf",
                            SdfDocument(MarkerModelSdf(marker, options)));
    WriteTextFileAtomically(
        model_folder / "model.config",
        ModelConfigText(name, "ArUco marker " + std::to_string(id) + " of " + map.dictionary));
    uris.push_back("model://" + name);
  }
  const std::filesystem::path world = folder / "world.sdf";
  WriteTextFileAtomically(world, SdfDocument(WorldWithIncludesSdf("markers", uris)));
  return world;
}

}  // namespace arucoslam
