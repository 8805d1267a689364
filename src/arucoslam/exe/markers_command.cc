// `arucoslam markers generate | sdf | import`: marker PNGs with a markers.json template,
// Gazebo model folders and a world from a markers.json, and import of a LOGNAV list.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>
#include <vector>

#include "arucoslam/exe/command.h"
#include "arucoslam/io/lognav_import.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/dictionary.h"
#include "arucoslam/markers/marker_image.h"
#include "arucoslam/markers/sdf_export.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

struct GenerateArgs {
  std::string dictionary = "DICT_4X4_50";
  std::string ids;
  int size_px = 600;  // side of the black square, pixels
  double quiet_zone_cells = 2.0;
  double size = 0.2;  // side of the black square in the template, metres
  std::string out;
};

struct SdfArgs {
  std::string markers;
  std::string out;
  int size_px = 600;
  double quiet_zone_cells = 2.0;
  double thickness = 0.002;  // metres
};

struct ImportArgs {
  std::string lognav;
  std::string out;
  std::string dictionary = "DICT_4X4_50";
};

MarkerImageOptions ImageOptions(int size_px, double quiet_zone_cells) {
  MarkerImageOptions image;
  image.marker_size_px = size_px;
  image.quiet_zone_cells = quiet_zone_cells;
  if (size_px < 16) throw InputError("--size-px", "expected at least 16 pixels");
  if (!(quiet_zone_cells >= 2.0)) {
    throw InputError("--quiet-zone-cells",
                     "expected at least 2 cells (narrower margins defeat the detector)");
  }
  return image;
}

std::vector<int> ParseIds(const std::string& text, const std::string& dictionary) {
  std::vector<int> ids;
  ParseIdRangeInto(text, ids);
  const int count = DictionaryFromName(dictionary, "--dictionary")->bytesList.rows;
  std::set<int> seen;
  for (const int id : ids) {
    if (id >= count) {
      throw InputError("--ids", "id " + std::to_string(id) + " is outside " + dictionary + " (0.." +
                                    std::to_string(count - 1) + ")");
    }
    if (!seen.insert(id).second) {
      throw InputError("--ids", "id " + std::to_string(id) + " is listed twice");
    }
  }
  return ids;
}

// The template: every marker fixed, identity orientation (lying flat, face up), in a row
// along world x with centres two box sides apart, so that `markers sdf` gives a valid
// world at once; the user replaces the poses by the measured ones.
MarkerMap TemplateMap(const std::vector<int>& ids, const GenerateArgs& args,
                      const MarkerImageOptions& image) {
  MarkerMap map;
  map.dictionary = args.dictionary;
  const double spacing = 2.0 * MarkerBoxSide(args.size, args.dictionary, image);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    MarkerInfo marker;
    marker.id = ids[i];
    marker.size = args.size;
    marker.world_from_marker.translation = Eigen::Vector3d(spacing * i, 0.0, 0.0);
    marker.fixed = true;
    map.markers[marker.id] = marker;
  }
  return map;
}

void RunGenerate(const GenerateArgs& args) {
  DictionaryFromName(args.dictionary, "--dictionary");
  if (!(args.size > 0.0) || !std::isfinite(args.size)) {
    throw InputError("--size", "expected a positive marker side in metres");
  }
  const MarkerImageOptions image = ImageOptions(args.size_px, args.quiet_zone_cells);
  const std::vector<int> ids = ParseIds(args.ids, args.dictionary);
  StagedDirectory out(args.out);
  for (const int id : ids) {
    const fs::path png = out.path() / MarkerTextureFileName(id);
    if (!cv::imwrite(png.string(), DrawMarkerImage(args.dictionary, id, image))) {
      throw InputError(args.out, "cannot write " + png.filename().string());
    }
  }
  WriteMarkerMapJson(TemplateMap(ids, args, image), out.path() / "markers.json");
  out.Commit();
  const int side_px = args.size_px + 2 * QuietZonePixels(args.dictionary, image);
  std::printf(
      "wrote %zu %s markers (%d px with the quiet zone) and a markers.json template "
      "(placeholder poses in a row along x) to %s\n",
      ids.size(), args.dictionary.c_str(), side_px, args.out.c_str());
}

void RunSdf(const SdfArgs& args) {
  const MarkerMap map = ReadMarkerMapJson(args.markers);
  const MarkerImageOptions image = ImageOptions(args.size_px, args.quiet_zone_cells);
  if (!(args.thickness > 0.0) || !std::isfinite(args.thickness)) {
    throw InputError("--thickness", "expected a positive thickness in metres");
  }
  StagedDirectory out(args.out);
  WriteMarkerSdfFolder(map, out.path(), image, args.thickness);
  WriteMarkerMapJson(map, out.path() / "markers.json");
  out.Commit();
  std::printf(
      "wrote %zu marker models and world.sdf to %s (add that folder to "
      "GZ_SIM_RESOURCE_PATH to load it in Gazebo)\n",
      map.markers.size(), args.out.c_str());
}

void RunImport(const ImportArgs& args) {
  LognavImportOptions options;
  options.dictionary = args.dictionary;
  DictionaryFromName(args.dictionary, "--dictionary");
  const MarkerMap map = ReadLognavMarkers(args.lognav, options);
  WriteMarkerMapJson(map, args.out);
  std::printf("imported %zu markers from %s into %s\n", map.markers.size(), args.lognav.c_str(),
              args.out.c_str());
}

}  // namespace

void AddMarkersCommand(CLI::App& app, int& exit_status) {
  CLI::App* markers = app.add_subcommand("markers", "Marker PNGs, marker maps and SDF models");
  markers->require_subcommand(1);

  auto generate_args = std::make_shared<GenerateArgs>();
  CLI::App* generate = markers->add_subcommand(
      "generate",
      "Write marker PNGs (white quiet zone included) and a markers.json template "
      "whose poses are placeholders (a row along x, face up): edit them");
  generate->add_option("--dictionary", generate_args->dictionary, "ArUco dictionary name")
      ->capture_default_str();
  generate->add_option("--ids", generate_args->ids, "ids, e.g. 0-9,12,20-22")->required();
  generate->add_option("--size-px", generate_args->size_px, "side of the black square in pixels")
      ->capture_default_str();
  generate
      ->add_option("--quiet-zone-cells", generate_args->quiet_zone_cells,
                   "white margin on each side, in marker cells (>= 2)")
      ->capture_default_str();
  generate
      ->add_option("--size", generate_args->size,
                   "printed side of the black square in metres (for markers.json)")
      ->capture_default_str();
  generate->add_option("--out", generate_args->out, "output folder (replaced)")->required();
  generate->callback([generate_args, &exit_status] {
    RunGenerate(*generate_args);
    exit_status = kExitOk;
  });

  auto sdf_args = std::make_shared<SdfArgs>();
  CLI::App* sdf = markers->add_subcommand(
      "sdf",
      "Write one Gazebo model folder per marker of a markers.json and a world.sdf "
      "including them (see docs/sdf_subset.md)");
  sdf->add_option("--markers", sdf_args->markers, "markers.json")->required();
  sdf->add_option("--out", sdf_args->out, "output folder (replaced)")->required();
  sdf->add_option("--size-px", sdf_args->size_px, "texture: side of the black square, pixels")
      ->capture_default_str();
  sdf->add_option("--quiet-zone-cells", sdf_args->quiet_zone_cells,
                  "texture: white margin on each side, in marker cells (>= 2)")
      ->capture_default_str();
  sdf->add_option("--thickness", sdf_args->thickness, "box thickness in metres")
      ->capture_default_str();
  sdf->callback([sdf_args, &exit_status] {
    RunSdf(*sdf_args);
    exit_status = kExitOk;
  });

  auto import_args = std::make_shared<ImportArgs>();
  CLI::App* import = markers->add_subcommand(
      "import",
      "Convert a FURG LOGNAV marker list (id, pos_x, pos_y, pos_z, yaw, size in cm; "
      "vertical markers facing (cos yaw, sin yaw, 0)) into markers.json");
  import->add_option("--lognav", import_args->lognav, "the LOGNAV JSON list")->required();
  import->add_option("--out", import_args->out, "markers.json to write")->required();
  import->add_option("--dictionary", import_args->dictionary, "ArUco dictionary of the markers")
      ->capture_default_str();
  import->callback([import_args, &exit_status] {
    RunImport(*import_args);
  exit_status = kExitOk;
});
}  // namespace arucoslam

}  // namespace arucoslam
