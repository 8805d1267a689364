#include "arucoslam/io/calibration.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
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
  FieldReader(YAML::Node root, std::string source)
      : root_(std::move(root)), source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  YAML::Node Find(const FieldPath& path) const {
    YAML::Node node = root_;  // reset() below rebinds `node`, never writes into root_
    for (const std::string& key : path) {
      if (!node.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
      const YAML::Node child = std::as_const(node)[key];
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
    const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
    if (!(rotation * rotation.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-5) ||
        rotation.determinant() < 0.0 ||
        !matrix.row(3).isApprox(Eigen::RowVector4d(0.0, 0.0, 0.0, 1.0))) {
      Fail(path, "not a rigid transform (expected an orthonormal rotation and last row 0 0 0 1)");
    }
    return Rigid3::FromMatrix(matrix);
  }

 private:
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

// Names of the distortion models each format uses, mapped to ours.
std::optional<DistortionModel> DistortionFromName(const std::string& name) {
  if (name == "radial-tangential" || name == "radtan" || name == "plumb_bob") {
    return DistortionModel::kRadTan;
  }
  if (name == "equidistant" || name == "fisheye") return DistortionModel::kEquidistant;
  if (name == "none") return DistortionModel::kNone;
  return std::nullopt;
}

// Coefficients each model takes: radtan k1 k2 p1 p2 [k3], equidistant k1..k4.
std::vector<double> ReadCoefficients(const FieldReader& fields, const FieldPath& path,
                                     DistortionModel model) {
  switch (model) {
    case DistortionModel::kNone:
      return fields.Has(path) ? fields.Numbers(path, 0, 0) : std::vector<double>{};
    case DistortionModel::kRadTan:
      return fields.Numbers(path, 4, 5);
    case DistortionModel::kEquidistant:
      return fields.Numbers(path, 4, 4);
  }
  return {};
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
  const std::string model_name = fields.Text({"distortion_model"});
  const std::optional<DistortionModel> model = DistortionFromName(model_name);
  if (!model) {
    fields.Fail({"distortion_model"},
                fmt::format("unknown model '{}' (expected radial-tangential, equidistant or none)",
                            model_name));
  }
  SetDistortion(*model, ReadCoefficients(fields, {"distortion_coefficients"}, *model), &camera);
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
  const std::vector<double> k = fields.Numbers(*matrix_path, 9, 9);
  if (k[1] != 0.0 || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    fields.Fail(*matrix_path, "expected [fx, 0, cx, 0, fy, cy, 0, 0, 1] (no skew)");
  }
  SetIntrinsics(fields, *matrix_path, k[0], k[4], k[2], k[5], camera);
}

CameraCalibration ParseRosCameraInfo(const FieldReader& fields) {
  CameraCalibration calibration;
  calibration.format = CalibrationFormat::kRosCameraInfo;
  CameraModel& camera = calibration.camera;
  camera.width = fields.Integer({"image_width"});
  camera.height = fields.Integer({"image_height"});
  RequirePositiveSize(fields, {"image_width"}, camera.width, camera.height);
  if (fields.Has({"camera_model"}) && fields.Text({"camera_model"}) != "pinhole") {
    fields.Fail({"camera_model"}, fmt::format("unsupported model '{}' (expected pinhole)",
                                              fields.Text({"camera_model"})));
  }
  ReadRosIntrinsics(fields, &camera);
  const std::string model_name = fields.Text({"distortion_model"});
  const std::optional<DistortionModel> model = DistortionFromName(model_name);
  if (!model) {
    fields.Fail(
        {"distortion_model"},
        fmt::format("unknown model '{}' (expected plumb_bob, equidistant or none)", model_name));
  }
  std::vector<double> coefficients;
  if (fields.Has({"distortion_coefficients"})) {
    coefficients = ReadCoefficients(fields, {"distortion_coefficients", "data"}, *model);
  } else if (fields.Has({"D"})) {
    coefficients = ReadCoefficients(fields, {"D"}, *model);
  } else if (*model == DistortionModel::kRadTan) {
    for (const char* name : {"k1", "k2", "p1", "p2"}) coefficients.push_back(fields.Number({name}));
    coefficients.push_back(fields.OptionalNumber({"k3"}).value_or(0.0));
  } else if (*model == DistortionModel::kEquidistant) {
    for (const char* name : {"k1", "k2", "k3", "k4"}) coefficients.push_back(fields.Number({name}));
  }
  SetDistortion(*model, coefficients, &camera);
  return calibration;
}

bool HasKeyWithPrefix(const YAML::Node& root, std::string_view prefix) {
  for (const auto& entry : root) {
    if (entry.first.IsScalar() && entry.first.Scalar().starts_with(prefix)) return true;
  }
  return false;
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
  }
  return "unknown";
}

CameraCalibration ParseCameraCalibration(std::string_view text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(WithoutOpenCvDirective(text));
  } catch (const YAML::Exception& error) {
    throw InputError(source, fmt::format("not valid YAML: line {}, column {}: {}",
                                         error.mark.line + 1, error.mark.column + 1, error.msg));
  }
  if (!root.IsMap()) {
    throw InputError(source, "not a camera calibration: expected a YAML map of fields");
  }
  const FieldReader fields(root, source);
  try {
    if (fields.Has({"image_width"})) return ParseRosCameraInfo(fields);
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
                   "ORB-SLAM3 settings (Camera.fx or Camera1.fx) or ROS camera_info "
                   "(image_width)");
}

CameraCalibration ReadCameraCalibration(const std::filesystem::path& path) {
  return ParseCameraCalibration(ReadTextFile(path), path.string());
}

CameraModel ReadCameraModel(const std::filesystem::path& path) {
  return ReadCameraCalibration(path).camera;
}

std::string FormatEuRoCSensorYaml(const CameraModel& camera, const Rigid3& body_from_cam) {
  if (!camera.Check()) throw std::invalid_argument("FormatEuRoCSensorYaml: invalid CameraModel");
  std::vector<double> coefficients;
  std::string model_name = "radial-tangential";
  switch (camera.model) {
    case DistortionModel::kNone:
      coefficients.assign(4, 0.0);
      break;
    case DistortionModel::kRadTan:
      coefficients.assign(camera.distortion.begin(),
                          camera.distortion.begin() + (camera.distortion[4] == 0.0 ? 4 : 5));
      break;
    case DistortionModel::kEquidistant:
      model_name = "equidistant";
      coefficients.assign(camera.distortion.begin(), camera.distortion.begin() + 4);
      break;
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
