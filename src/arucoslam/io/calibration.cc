#include "arucoslam/io/calibration.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <opencv2/core.hpp>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

// A field's location: one key per nesting level. ORB-SLAM3 keys contain dots themselves
// ("Camera.fx"), so a path is a list, not a dotted string.
using FieldPath = std::vector<std::string>;

std::string FieldName(const FieldPath& path) { return fmt::format("{}", fmt::join(path, ".")); }

// Strict number parsing: the whole scalar must be a finite number.
std::optional<double> ParseDouble(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::optional<int> ParseInt(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

// What a node holds, for "found ..." in messages.
std::string Describe(const YAML::Node& node) {
  if (node.IsScalar()) return fmt::format("'{}'", node.Scalar());
  if (node.IsSequence()) return fmt::format("a list of {}", node.size());
  if (node.IsMap()) return "a map";
  return "nothing";
}

// Typed access to the fields of one YAML map, throwing InputError(source, "<field>: ...").
class FieldReader {
 public:
  // A map's entry `key`, or a sequence's item at index `key` (Kalibr's matrix rows).
  static YAML::Node Child(const YAML::Node& node, const std::string& key) {
    if (node.IsMap()) return node[key];
    const std::optional<int> index = ParseInt(key);
    if (node.IsSequence() && index && *index >= 0 &&
        static_cast<std::size_t>(*index) < node.size()) {
      return node[static_cast<std::size_t>(*index)];
    }
    return YAML::Node(YAML::NodeType::Undefined);
  }

  FieldReader(YAML::Node root, std::string source)
      : root_(std::move(root)), source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  YAML::Node Find(const FieldPath& path) const {
    YAML::Node node = root_;  // reset() below rebinds `node`, never writes into root_
    for (const std::string& key : path) {
      const YAML::Node child = Child(node, key);
      if (!child.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
      node.reset(child);
    }
    return node;
  }
  bool Has(const FieldPath& path) const { return Find(path).IsDefined(); }

  [[noreturn]] void Fail(const FieldPath& path, const std::string& message) const {
    throw InputError(source_, fmt::format("{}: {}", FieldName(path), message));
  }

  YAML::Node Require(const FieldPath& path) const {
    YAML::Node node = Find(path);
    if (!node.IsDefined() || node.IsNull()) Fail(path, "missing");
    return node;
  }

  double Number(const FieldPath& path) const {
    const YAML::Node node = Require(path);
    const std::optional<double> value = node.IsScalar() ? ParseDouble(node.Scalar()) : std::nullopt;
    if (!value) Fail(path, fmt::format("expected a number, found {}", Describe(node)));
    return *value;
  }
  std::optional<double> OptionalNumber(const FieldPath& path) const {
    if (!Has(path)) return std::nullopt;
    return Number(path);
  }

  int Integer(const FieldPath& path) const {
    const YAML::Node node = Require(path);
    const std::optional<int> value = node.IsScalar() ? ParseInt(node.Scalar()) : std::nullopt;
    if (!value) Fail(path, fmt::format("expected an integer, found {}", Describe(node)));
    return *value;
  }

  std::string Text(const FieldPath& path) const {
    const YAML::Node node = Require(path);
    if (!node.IsScalar()) Fail(path, fmt::format("expected a name, found {}", Describe(node)));
    return node.Scalar();
  }

  // A list of between min_count and max_count numbers.
  std::vector<double> Numbers(const FieldPath& path, std::size_t min_count,
                              std::size_t max_count) const {
    const YAML::Node node = Require(path);
    const std::string expected = min_count == max_count
                                     ? fmt::format("{} numbers", min_count)
                                     : fmt::format("{} to {} numbers", min_count, max_count);
    if (!node.IsSequence())
      Fail(path, fmt::format("expected {}, found {}", expected, Describe(node)));
    if (node.size() < min_count || node.size() > max_count) {
      Fail(path, fmt::format("expected {}, found {}", expected, node.size()));
    }
    std::vector<double> numbers;
    for (std::size_t i = 0; i < node.size(); ++i) {
      const YAML::Node item = node[i];
      const std::optional<double> value =
          item.IsScalar() ? ParseDouble(item.Scalar()) : std::nullopt;
      if (!value) {
        Fail(path, fmt::format("item {}: expected a number, found {}", i + 1, Describe(item)));
      }
      numbers.push_back(*value);
    }
    return numbers;
  }

  // A 4x4 rigid transform stored as {rows: 4, cols: 4, data: [16 numbers, row major]}
  // (EuRoC, and OpenCV's !!opencv-matrix).
  Rigid3 RigidMatrix(const FieldPath& path) const {
    FieldPath rows = path, cols = path, data = path;
    rows.push_back("rows");
    cols.push_back("cols");
    data.push_back("data");
    if (Integer(rows) != 4) Fail(rows, "expected 4");
    if (Integer(cols) != 4) Fail(cols, "expected 4");
    const std::vector<double> values = Numbers(data, 16, 16);
    Eigen::Matrix4d matrix;
    for (int i = 0; i < 16; ++i) matrix(i / 4, i % 4) = values[i];
    return Rigid(path, matrix);
  }

  // A 4x4 rigid transform stored as a list of 4 rows of 4 numbers (Kalibr).
  Rigid3 RigidRows(const FieldPath& path) const {
    const YAML::Node node = Require(path);
    if (!node.IsSequence() || node.size() != 4) {
      Fail(path, fmt::format("expected 4 rows of 4 numbers, found {}", Describe(node)));
    }
    Eigen::Matrix4d matrix;
    for (int r = 0; r < 4; ++r) {
      FieldPath row = path;
      row.push_back(std::to_string(r));  // a sequence index; Numbers() reads it through Find()
      const std::vector<double> values = Numbers(row, 4, 4);
      for (int c = 0; c < 4; ++c) matrix(r, c) = values[c];
    }
    return Rigid(path, matrix);
  }

 private:
  Rigid3 Rigid(const FieldPath& path, const Eigen::Matrix4d& matrix) const {
    const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
    if (!(rotation * rotation.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-5) ||
        rotation.determinant() < 0.0 ||
        !matrix.row(3).isApprox(Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0))) {
      Fail(path, "not a rigid transform (expected an orthonormal rotation and last row 0 0 0 1)");
    }
    return Rigid3::FromMatrix(matrix);
  }

  YAML::Node root_;
  std::string source_;
};

void RequirePositiveSize(const FieldReader& fields, const FieldPath& path, int width, int height) {
  if (width <= 0 || height <= 0) {
    fields.Fail(path,
                fmt::format("width and height must be positive, found {} x {}", width, height));
  }
}

void SetIntrinsics(const FieldReader& fields, const FieldPath& path, double fx, double fy,
                   double cx, double cy, CameraModel* camera) {
  if (!(fx > 0.0) || !(fy > 0.0)) {
    fields.Fail(path,
                fmt::format("focal lengths must be positive, found fx = {}, fy = {}", fx, fy));
  }
  camera->fx = fx;
  camera->fy = fy;
  camera->cx = cx;
  camera->cy = cy;
}

// Sets the distortion; coefficients that are all zero mean no distortion.
void SetDistortion(DistortionModel model, const std::vector<double>& coefficients,
                   CameraModel* camera) {
  camera->distortion = {};
  bool all_zero = true;
  for (std::size_t i = 0; i < coefficients.size(); ++i) {
    camera->distortion[i] = coefficients[i];
    all_zero = all_zero && coefficients[i] == 0.0;
  }
  camera->model = all_zero ? DistortionModel::kNone : model;
}

// Names of the distortion models each format uses, mapped to ours. The first name of each model
// is the one sensor.yaml files are written with.
struct ModelName {
  std::string_view name;
  DistortionModel model;
};
constexpr ModelName kModelNames[] = {
    {"radial-tangential", DistortionModel::kRadTan},
    {"equidistant", DistortionModel::kEquidistant},
    {"opencv_rational8", DistortionModel::kRational},
    {"opencv_thin_prism12", DistortionModel::kThinPrism},
    {"opencv_tilted14", DistortionModel::kTilted},
    {"none", DistortionModel::kNone},
    {"radtan", DistortionModel::kRadTan},                 // Kalibr
    {"plumb_bob", DistortionModel::kRadTan},              // ROS
    {"rational_polynomial", DistortionModel::kRational},  // ROS
    {"fisheye", DistortionModel::kEquidistant},
};

std::optional<DistortionModel> DistortionFromName(const std::string& name) {
  for (const ModelName& entry : kModelNames) {
    if (entry.name == name) return entry.model;
  }
  return std::nullopt;
}

std::string_view SensorYamlModelName(DistortionModel model) {
  for (const ModelName& entry : kModelNames) {
    if (entry.model == model) return entry.name;
  }
  return "none";
}

// Reads the model named at `path`; `expected` lists the names the format uses, for the error.
// A format that knows only some models lists them in `allowed` (empty: all).
DistortionModel ReadModelName(const FieldReader& fields, const FieldPath& path,
                              std::string_view expected,
                              std::initializer_list<DistortionModel> allowed = {}) {
  const std::string name = fields.Text(path);
  const std::optional<DistortionModel> model = DistortionFromName(name);
  if (!model ||
      (allowed.size() > 0 && std::find(allowed.begin(), allowed.end(), *model) == allowed.end())) {
    fields.Fail(path, fmt::format("unknown model '{}' (expected {})", name, expected));
  }
  return *model;
}

// Coefficients each model takes: radtan k1 k2 p1 p2 [k3], equidistant k1..k4, rational 8,
// thin prism 12, tilted 14 (OpenCV's order).
std::vector<double> ReadCoefficients(const FieldReader& fields, const FieldPath& path,
                                     DistortionModel model) {
  switch (model) {
    case DistortionModel::kNone:
      return fields.Has(path) ? fields.Numbers(path, 0, 0) : std::vector<double>{};
    case DistortionModel::kRadTan:
      return fields.Numbers(path, 4, 5);
    case DistortionModel::kEquidistant:
    case DistortionModel::kRational:
    case DistortionModel::kThinPrism:
    case DistortionModel::kTilted: {
      const std::size_t count = NumDistortionCoefficients(model);
      return fields.Numbers(path, count, count);
    }
  }
  return {};
}

// OpenCV's pinhole models by the number of coefficients a distortion vector holds.
std::optional<DistortionModel> OpenCvModelForCount(std::size_t count) {
  switch (count) {
    case 0:
      return DistortionModel::kNone;
    case 4:
    case 5:
      return DistortionModel::kRadTan;
    case 8:
      return DistortionModel::kRational;
    case 12:
      return DistortionModel::kThinPrism;
    case 14:
      return DistortionModel::kTilted;
  }
  return std::nullopt;
}

void ReadOptionalRate(const FieldReader& fields, const FieldPath& path, CameraModel* camera) {
  const std::optional<double> rate = fields.OptionalNumber(path);
  if (rate && *rate < 0.0) fields.Fail(path, fmt::format("must not be negative, found {}", *rate));
  camera->rate_hz = rate.value_or(0.0);
}

CameraCalibration ParseEuRoC(const FieldReader& fields) {
  CameraCalibration calibration;
  calibration.format = CalibrationFormat::kEuRoC;
  CameraModel& camera = calibration.camera;
  if (fields.Has({"camera_model"}) && fields.Text({"camera_model"}) != "pinhole") {
    fields.Fail({"camera_model"}, fmt::format("unsupported model '{}' (expected pinhole)",
                                              fields.Text({"camera_model"})));
  }
  const std::vector<double> intrinsics = fields.Numbers({"intrinsics"}, 4, 4);
  SetIntrinsics(fields, {"intrinsics"}, intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3],
                &camera);
  const std::vector<double> resolution = fields.Numbers({"resolution"}, 2, 2);
  for (const double value : resolution) {
    if (value != std::floor(value)) {
      fields.Fail({"resolution"}, fmt::format("expected whole pixels, found {}", value));
    }
  }
  camera.width = static_cast<int>(resolution[0]);
  camera.height = static_cast<int>(resolution[1]);
  RequirePositiveSize(fields, {"resolution"}, camera.width, camera.height);
  const DistortionModel model = ReadModelName(
      fields, {"distortion_model"},
      "radial-tangential, equidistant, opencv_rational8, opencv_thin_prism12, opencv_tilted14 "
      "or none");
  SetDistortion(model, ReadCoefficients(fields, {"distortion_coefficients"}, model), &camera);
  ReadOptionalRate(fields, {"rate_hz"}, &camera);
  if (fields.Has({"T_BS"})) calibration.body_from_cam = fields.RigidMatrix({"T_BS"});
  return calibration;
}

CameraCalibration ParseOrbSlam3(const FieldReader& fields) {
  CameraCalibration calibration;
  calibration.format = CalibrationFormat::kOrbSlam3;
  CameraModel& camera = calibration.camera;
  // File.version "1.0" puts the intrinsics under Camera1.*; older files under Camera.*.
  std::string prefix = "Camera.";
  if (fields.Has({"File.version"})) {
    const std::string version = fields.Text({"File.version"});
    if (version != "1.0") {
      fields.Fail({"File.version"},
                  fmt::format("unsupported version '{}' (expected 1.0)", version));
    }
    prefix = "Camera1.";
  } else if (fields.Has({"Camera1.fx"})) {
    prefix = "Camera1.";
  }
  const std::string type = fields.Has({"Camera.type"}) ? fields.Text({"Camera.type"}) : "PinHole";
  SetIntrinsics(fields, {prefix + "fx"}, fields.Number({prefix + "fx"}),
                fields.Number({prefix + "fy"}), fields.Number({prefix + "cx"}),
                fields.Number({prefix + "cy"}), &camera);
  camera.width = fields.Integer({"Camera.width"});
  camera.height = fields.Integer({"Camera.height"});
  RequirePositiveSize(fields, {"Camera.width"}, camera.width, camera.height);
  if (type == "PinHole") {
    // Distortion is optional; when k1 is given, k2 p1 p2 are required and k3 optional.
    if (fields.Has({prefix + "k1"})) {
      std::vector<double> coefficients;
      for (const char* name : {"k1", "k2", "p1", "p2"}) {
        coefficients.push_back(fields.Number({prefix + name}));
      }
      coefficients.push_back(fields.OptionalNumber({prefix + "k3"}).value_or(0.0));
      SetDistortion(DistortionModel::kRadTan, coefficients, &camera);
    }
  } else if (type == "KannalaBrandt8") {
    std::vector<double> coefficients;
    for (const char* name : {"k1", "k2", "k3", "k4"}) {
      coefficients.push_back(fields.Number({prefix + name}));
    }
    SetDistortion(DistortionModel::kEquidistant, coefficients, &camera);
  } else if (type != "Rectified") {
    fields.Fail(
        {"Camera.type"},
        fmt::format("unknown model '{}' (expected PinHole, KannalaBrandt8 or Rectified)", type));
  }
  ReadOptionalRate(fields, {"Camera.fps"}, &camera);
  for (const char* key : {"IMU.T_b_c1", "Tbc"}) {
    if (fields.Has({key})) {
      calibration.body_from_cam = fields.RigidMatrix({key});
      break;
    }
  }
  return calibration;
}

// image_width and image_height (ROS camera_info, OpenCV FileStorage).
void ReadImageSize(const FieldReader& fields, CameraModel* camera) {
  camera->width = fields.Integer({"image_width"});
  camera->height = fields.Integer({"image_height"});
  RequirePositiveSize(fields, {"image_width"}, camera->width, camera->height);
}

// A 3x3 camera matrix as 9 numbers, row major, without skew.
void ReadCameraMatrix(const FieldReader& fields, const FieldPath& path, CameraModel* camera) {
  const std::vector<double> k = fields.Numbers(path, 9, 9);
  if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    fields.Fail(path, "expected [fx, 0, cx, 0, fy, cy, 0, 0, 1] (no skew)");
  }
  SetIntrinsics(fields, path, k[0], k[4], k[2], k[5], camera);
}

// ROS intrinsics: camera_matrix.data (camera_calibration_parsers), else a flat K, else fx ...
void ReadRosIntrinsics(const FieldReader& fields, CameraModel* camera) {
  std::optional<FieldPath> matrix_path;
  if (fields.Has({"camera_matrix"})) {
    matrix_path = FieldPath{"camera_matrix", "data"};
  } else if (fields.Has({"K"})) {
    matrix_path = FieldPath{"K"};
  }
  if (!matrix_path) {
    SetIntrinsics(fields, {"fx"}, fields.Number({"fx"}), fields.Number({"fy"}),
                  fields.Number({"cx"}), fields.Number({"cy"}), camera);
    return;
  }
  ReadCameraMatrix(fields, *matrix_path, camera);
}

CameraCalibration ParseRosCameraInfo(const FieldReader& fields) {
  CameraCalibration calibration;
  calibration.format = CalibrationFormat::kRosCameraInfo;
  CameraModel& camera = calibration.camera;
  ReadImageSize(fields, &camera);
  if (fields.Has({"camera_model"}) && fields.Text({"camera_model"}) != "pinhole") {
    fields.Fail({"camera_model"}, fmt::format("unsupported model '{}' (expected pinhole)",
                                              fields.Text({"camera_model"})));
  }
  ReadRosIntrinsics(fields, &camera);
  const DistortionModel model = ReadModelName(
      fields, {"distortion_model"}, "plumb_bob, rational_polynomial, equidistant or none");
  std::vector<double> coefficients;
  if (fields.Has({"distortion_coefficients"})) {
    coefficients = ReadCoefficients(fields, {"distortion_coefficients", "data"}, model);
  } else if (fields.Has({"D"})) {
    coefficients = ReadCoefficients(fields, {"D"}, model);
  } else if (model == DistortionModel::kRadTan) {
    for (const char* name : {"k1", "k2", "p1", "p2"}) coefficients.push_back(fields.Number({name}));
    coefficients.push_back(fields.OptionalNumber({"k3"}).value_or(0.0));
  } else if (model == DistortionModel::kEquidistant) {
    for (const char* name : {"k1", "k2", "k3", "k4"}) coefficients.push_back(fields.Number({name}));
  } else if (model != DistortionModel::kNone) {
    fields.Require({"D"});  // the rational model has no flat per-coefficient keys
  }
  SetDistortion(model, coefficients, &camera);
  return calibration;
}

// OpenCV FileStorage (YAML or XML, as OpenCV's calibration sample writes it): image_width,
// image_height, camera_matrix and distortion_coefficients as !!opencv-matrix nodes; the model
// follows from the number of coefficients (4 or 5, 8, 12, 14), or is the fisheye model when
// fisheye_model is 1.
CameraCalibration ParseOpenCvStorage(const FieldReader& fields) {
  CameraCalibration calibration;
  calibration.format = CalibrationFormat::kOpenCv;
  CameraModel& camera = calibration.camera;
  ReadImageSize(fields, &camera);
  if (fields.Integer({"camera_matrix", "rows"}) != 3 ||
      fields.Integer({"camera_matrix", "cols"}) != 3) {
    fields.Fail({"camera_matrix"}, "expected a 3x3 matrix");
  }
  ReadCameraMatrix(fields, {"camera_matrix", "data"}, &camera);
  const FieldPath data = {"distortion_coefficients", "data"};
  const bool fisheye = fields.Has({"fisheye_model"}) && fields.Integer({"fisheye_model"}) != 0;
  std::vector<double> coefficients;
  if (fields.Has({"distortion_coefficients"})) {
    const std::size_t size =
        static_cast<std::size_t>(fields.Integer({"distortion_coefficients", "rows"})) *
        fields.Integer({"distortion_coefficients", "cols"});
    if (size > 0) coefficients = fields.Numbers(data, size, size);
  }
  const std::optional<DistortionModel> model =
      fisheye
          ? (coefficients.size() == 4 ? std::optional(DistortionModel::kEquidistant) : std::nullopt)
          : OpenCvModelForCount(coefficients.size());
  if (!model) {
    fields.Fail(data,
                fmt::format("expected {}, found {} numbers",
                            fisheye ? "4 (fisheye)" : "0, 4, 5, 8, 12 or 14", coefficients.size()));
  }
  SetDistortion(*model, coefficients, &camera);
  return calibration;
}

// Kalibr camchain.yaml: the first camera, cam0 (camera_model pinhole, intrinsics, resolution,
// distortion_model radtan / equidistant / none, distortion_coeffs, T_cam_imu).
CameraCalibration ParseKalibr(const FieldReader& fields) {
  CameraCalibration calibration;
  calibration.format = CalibrationFormat::kKalibr;
  CameraModel& camera = calibration.camera;
  const std::string model_name = fields.Text({"cam0", "camera_model"});
  if (model_name != "pinhole") {
    fields.Fail({"cam0", "camera_model"},
                fmt::format("unsupported model '{}' (expected pinhole)", model_name));
  }
  const std::vector<double> intrinsics = fields.Numbers({"cam0", "intrinsics"}, 4, 4);
  SetIntrinsics(fields, {"cam0", "intrinsics"}, intrinsics[0], intrinsics[1], intrinsics[2],
                intrinsics[3], &camera);
  const std::vector<double> resolution = fields.Numbers({"cam0", "resolution"}, 2, 2);
  camera.width = static_cast<int>(resolution[0]);
  camera.height = static_cast<int>(resolution[1]);
  if (resolution[0] != camera.width || resolution[1] != camera.height) {
    fields.Fail({"cam0", "resolution"}, "expected whole pixels");
  }
  RequirePositiveSize(fields, {"cam0", "resolution"}, camera.width, camera.height);
  const DistortionModel model = ReadModelName(
      fields, {"cam0", "distortion_model"}, "radtan, equidistant or none",
      {DistortionModel::kRadTan, DistortionModel::kEquidistant, DistortionModel::kNone});
  SetDistortion(model, ReadCoefficients(fields, {"cam0", "distortion_coeffs"}, model), &camera);
  if (fields.Has({"cam0", "T_cam_imu"})) {
    calibration.body_from_cam = fields.RigidRows({"cam0", "T_cam_imu"}).Inverse();
  }
  return calibration;
}

bool HasKeyWithPrefix(const YAML::Node& root, std::string_view prefix) {
  for (const auto& entry : root) {
    if (entry.first.IsScalar() && entry.first.Scalar().starts_with(prefix)) return true;
  }
  return false;
}

// An OpenCV FileStorage node as the YAML node yaml-cpp would give for the same content, so that
// XML files go through the same field readers. Numbers become their shortest exact text.
YAML::Node ToYaml(const cv::FileNode& node) {
  if (node.isMap()) {
    YAML::Node map(YAML::NodeType::Map);
    for (const cv::FileNode& child : node) map[child.name()] = ToYaml(child);
    return map;
  }
  if (node.isSeq()) {
    YAML::Node sequence(YAML::NodeType::Sequence);
    for (const cv::FileNode& child : node) sequence.push_back(ToYaml(child));
    return sequence;
  }
  if (node.isInt()) return YAML::Node(std::to_string(static_cast<int>(node)));
  if (node.isReal()) return YAML::Node(fmt::format("{}", static_cast<double>(node)));
  if (node.isString()) return YAML::Node(node.string());
  return YAML::Node(YAML::NodeType::Null);
}

bool LooksLikeXml(std::string_view text) {
  const std::size_t start = text.find_first_not_of(" \t\r\n");
  return start != std::string_view::npos && text.substr(start, 1) == "<";
}

YAML::Node LoadXml(std::string_view text, const std::string& source) {
  try {
    const cv::FileStorage storage(std::string(text), cv::FileStorage::READ |
                                                         cv::FileStorage::MEMORY |
                                                         cv::FileStorage::FORMAT_XML);
    return ToYaml(storage.root());
  } catch (const cv::Exception& error) {
    throw InputError(source, fmt::format("not valid OpenCV XML: {}", error.err));
  }
}

// yaml-cpp rejects OpenCV's "%YAML:1.0" directive: blank it (keeping line numbers).
std::string WithoutOpenCvDirective(std::string_view text) {
  std::string cleaned(text);
  const std::size_t start = cleaned.find_first_not_of(" \t\r\n");
  if (start != std::string::npos && cleaned.compare(start, 5, "%YAML") == 0) {
    const std::size_t end = cleaned.find('\n', start);
    cleaned.erase(start, end == std::string::npos ? std::string::npos : end - start);
  }
  return cleaned;
}

}  // namespace

std::string CalibrationFormatName(CalibrationFormat format) {
  switch (format) {
    case CalibrationFormat::kEuRoC:
      return "EuRoC sensor.yaml";
    case CalibrationFormat::kOrbSlam3:
      return "ORB-SLAM3 settings";
    case CalibrationFormat::kRosCameraInfo:
      return "ROS camera_info";
    case CalibrationFormat::kOpenCv:
      return "OpenCV FileStorage";
    case CalibrationFormat::kKalibr:
      return "Kalibr camchain";
  }
  return "unknown";
}

CameraCalibration ParseCameraCalibration(std::string_view text, const std::string& source) {
  YAML::Node root;
  if (LooksLikeXml(text)) {
    root = LoadXml(text, source);
  } else {
    try {
      root = YAML::Load(WithoutOpenCvDirective(text));
    } catch (const YAML::Exception& error) {
      throw InputError(source, fmt::format("not valid YAML: line {}, column {}: {}",
                                           error.mark.line + 1, error.mark.column + 1, error.msg));
    }
  }
  if (!root.IsMap()) {
    throw InputError(source, "not a camera calibration: expected a YAML map of fields");
  }
  const FieldReader fields(root, source);
  try {
    // ROS camera_info and OpenCV FileStorage share image_width and camera_matrix; only ROS
    // names its distortion model.
    if (fields.Has({"image_width"})) {
      return fields.Has({"distortion_model"}) ? ParseRosCameraInfo(fields)
                                              : ParseOpenCvStorage(fields);
    }
    if (fields.Find({"cam0"}).IsMap()) return ParseKalibr(fields);
    if (HasKeyWithPrefix(root, "Camera.") || HasKeyWithPrefix(root, "Camera1.")) {
      return ParseOrbSlam3(fields);
    }
    const YAML::Node sensor_type = fields.Find({"sensor_type"});
    if (fields.Has({"intrinsics"}) || fields.Has({"resolution"}) ||
        fields.Has({"distortion_coefficients"}) ||
        (sensor_type.IsScalar() && sensor_type.Scalar() == "camera")) {
      return ParseEuRoC(fields);
    }
  } catch (const YAML::Exception& error) {
    throw InputError(source, fmt::format("unreadable YAML: {}", error.what()));
  }
  throw InputError(source,
                   "not a camera calibration: expected EuRoC sensor.yaml (intrinsics), "
                   "ORB-SLAM3 settings (Camera.fx or Camera1.fx), ROS camera_info or OpenCV "
                   "FileStorage (image_width) or Kalibr camchain (cam0)");
}

CameraCalibration ReadCameraCalibration(const std::filesystem::path& path) {
  return ParseCameraCalibration(ReadTextFile(path), path.string());
}

CameraModel ReadCameraModel(const std::filesystem::path& path) {
  return ReadCameraCalibration(path).camera;
}

std::string FormatEuRoCSensorYaml(const CameraModel& camera, const Rigid3& body_from_cam) {
  if (!camera.Check()) throw std::invalid_argument("FormatEuRoCSensorYaml: invalid CameraModel");
  std::vector<double> coefficients = camera.DistortionCoefficients();
  std::string_view model_name = SensorYamlModelName(camera.model);
  if (camera.model == DistortionModel::kNone) {
    model_name = SensorYamlModelName(DistortionModel::kRadTan);
    coefficients.assign(4, 0.0);
  } else if (camera.model == DistortionModel::kRadTan && coefficients[4] == 0.0) {
    coefficients.pop_back();
  }
  const Eigen::Matrix4d matrix = body_from_cam.ToMatrix();
  std::string rows;
  for (int r = 0; r < 4; ++r) {
    rows += fmt::format("{}{}, {}, {}, {}", r == 0 ? "" : ",\n         ", matrix(r, 0),
                        matrix(r, 1), matrix(r, 2), matrix(r, 3));
  }
  return fmt::format(
      "%YAML:1.0\n"
      "# General sensor definitions.\n"
      "sensor_type: camera\n"
      "comment: camera written by arucoslam\n"
      "\n"
      "# Sensor extrinsics wrt. the body-frame.\n"
      "T_BS:\n"
      "  cols: 4\n"
      "  rows: 4\n"
      "  data: [{}]\n"
      "\n"
      "# Camera specific definitions.\n"
      "rate_hz: {}\n"
      "resolution: [{}, {}]\n"
      "camera_model: pinhole\n"
      "intrinsics: [{}, {}, {}, {}] #fu, fv, cu, cv\n"
      "distortion_model: {}\n"
      "distortion_coefficients: [{}]\n",
      rows, camera.rate_hz, camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy,
      model_name, fmt::join(coefficients, ", "));
}

void WriteEuRoCSensorYaml(const CameraModel& camera, const std::filesystem::path& path,
                          const Rigid3& body_from_cam) {
  WriteTextFileAtomically(path, FormatEuRoCSensorYaml(camera, body_from_cam));
}

}  // namespace arucoslam
