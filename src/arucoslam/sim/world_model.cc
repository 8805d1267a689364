#include "arucoslam/sim/world_model.h"

#include <sdf/Box.hh>
#include <sdf/Console.hh>
#include <sdf/Element.hh>
#include <sdf/Cylinder.hh>
#include <sdf/Geometry.hh>
#include <sdf/Light.hh>
#include <sdf/Link.hh>
#include <sdf/Material.hh>
#include <sdf/Model.hh>
#include <sdf/ParserConfig.hh>
#include <sdf/Pbr.hh>
#include <sdf/Plane.hh>
#include <sdf/Root.hh>
#include <sdf/Visual.hh>
#include <sdf/World.hh>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "arucoslam/util/error.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

Rigid3 ToRigid3(const ignition::math::Pose3d& pose) {
  const auto& q = pose.Rot();
  const auto& t = pose.Pos();
  return Rigid3(Eigen::Quaterniond(q.W(), q.X(), q.Y(), q.Z()),
                Eigen::Vector3d(t.X(), t.Y(), t.Z()));
}

std::string FirstError(const sdf::Errors& errors) {
  std::ostringstream text;
  text << errors.front().Message();
  if (errors.size() > 1) text << " (and " << errors.size() - 1 << " more errors)";
  return text.str();
}

// Resolves a SemanticPose against its default frame; throws on an unresolvable pose.
Rigid3 Resolve(const sdf::SemanticPose& semantic_pose, const std::string& source,
               const std::string& what) {
  ignition::math::Pose3d pose;
  const sdf::Errors errors = semantic_pose.Resolve(pose);
  if (!errors.empty()) {
    throw InputError(source, "cannot resolve the pose of " + what + ": " + FirstError(errors));
  }
  return ToRigid3(pose);
}

Eigen::Vector4d ToVector(const ignition::math::Color& color) {
  return Eigen::Vector4d(color.R(), color.G(), color.B(), color.A());
}

// Rotation taking +z to the unit vector `normal` (identity when already +z).
Eigen::Quaterniond RotationFromZTo(const Eigen::Vector3d& normal) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), normal.normalized());
}

fs::path ResolveTexture(const std::string& uri, const std::string& material_file,
                        const fs::path& base_dir, const std::string& source) {
  std::string path_text = uri;
  if (path_text.rfind("file://", 0) == 0) path_text = path_text.substr(7);
  fs::path path(path_text);
  if (path.is_relative()) {
    const fs::path dir =
        material_file.empty() ? base_dir : fs::path(material_file).parent_path();
    path = dir / path;
  }
  std::error_code error;
  if (!fs::is_regular_file(path, error)) {
    throw InputError(source, "texture '" + uri + "' not found (looked for " +
                                 path.string() + ")");
  }
  return fs::absolute(path).lexically_normal();
}

struct Loader {
  std::string source;
  fs::path base_dir;
  WorldModel* world = nullptr;
  fs::path world_file;  // empty for a world from a string

  // Records a file of the world (not the world file itself), once.
  void AddFile(const fs::path& file) {
    if (file == world_file) return;
    if (std::find(world->files.begin(), world->files.end(), file) == world->files.end()) {
      world->files.push_back(file);
    }
  }
  void AddVisual(const sdf::Visual& visual, const Rigid3& world_from_link,
                 const std::string& prefix);
  void AddModel(const sdf::Model& model, const Rigid3& world_from_parent,
                const std::string& prefix);
};

void Loader::AddVisual(const sdf::Visual& visual, const Rigid3& world_from_link,
                       const std::string& prefix) {
  const std::string name = prefix + visual.Name();
  const Rigid3 world_from_visual =
      world_from_link * Resolve(visual.SemanticPose(), source, "visual " + name);
  const sdf::Geometry* geometry = visual.Geom();
  WorldPrimitive primitive;
  primitive.name = name;
  primitive.world_from_shape = world_from_visual;
  if (geometry != nullptr && geometry->Type() == sdf::GeometryType::BOX) {
    const auto size = geometry->BoxShape()->Size();
    primitive.type = ShapeType::kBox;
    primitive.size = Eigen::Vector3d(size.X(), size.Y(), size.Z());
  } else if (geometry != nullptr && geometry->Type() == sdf::GeometryType::PLANE) {
    const auto* plane = geometry->PlaneShape();
    const auto normal = plane->Normal();
    primitive.type = ShapeType::kPlane;
    primitive.size = Eigen::Vector3d(plane->Size().X(), plane->Size().Y(), 0.0);
    primitive.world_from_shape =
        world_from_visual *
        Rigid3(RotationFromZTo(Eigen::Vector3d(normal.X(), normal.Y(), normal.Z())),
               Eigen::Vector3d::Zero());
  } else if (geometry != nullptr && geometry->Type() == sdf::GeometryType::CYLINDER) {
    const auto* cylinder = geometry->CylinderShape();
    primitive.type = ShapeType::kCylinder;
    primitive.size = Eigen::Vector3d(2.0 * cylinder->Radius(), 2.0 * cylinder->Radius(),
                                     cylinder->Length());
  } else {
    ARUCOSLAM_LOG_WARN("{}: visual {} has geometry outside the rendered subset; skipped",
                       source, name);
    return;
  }
  if (const sdf::Material* material = visual.Material()) {
    // Absent colours: diffuse white (the texture as it is), ambient = diffuse.
    const sdf::ElementPtr element = material->Element();
    const bool has_diffuse = element == nullptr || element->HasElement("diffuse");
    const bool has_ambient = element == nullptr || element->HasElement("ambient");
    if (has_diffuse) primitive.diffuse = ToVector(material->Diffuse());
    primitive.ambient = has_ambient ? ToVector(material->Ambient()) : primitive.diffuse;
    const sdf::Pbr* pbr = material->PbrMaterial();
    const sdf::PbrWorkflow* workflow =
        pbr == nullptr ? nullptr : pbr->Workflow(sdf::PbrWorkflowType::METAL);
    if (workflow != nullptr && !workflow->AlbedoMap().empty()) {
      primitive.texture =
          ResolveTexture(workflow->AlbedoMap(), material->FilePath(), base_dir, source);
      AddFile(primitive.texture);
    }
  }
  world->primitives.push_back(std::move(primitive));
}

void Loader::AddModel(const sdf::Model& model, const Rigid3& world_from_parent,
                      const std::string& prefix) {
  const std::string name = prefix + model.Name();
  if (model.Element() != nullptr && !model.Element()->FilePath().empty()) {
    const fs::path model_file = fs::absolute(model.Element()->FilePath()).lexically_normal();
    AddFile(model_file);
    std::error_code error;
    if (fs::is_regular_file(model_file.parent_path() / "model.config", error)) {
      AddFile(model_file.parent_path() / "model.config");
    }
  }
  const Rigid3 world_from_model =
      world_from_parent * Resolve(model.SemanticPose(), source, "model " + name);
  for (uint64_t l = 0; l < model.LinkCount(); ++l) {
    const sdf::Link* link = model.LinkByIndex(l);
    const std::string link_name = name + "::" + link->Name();
    const Rigid3 world_from_link =
        world_from_model * Resolve(link->SemanticPose(), source, "link " + link_name);
    for (uint64_t v = 0; v < link->VisualCount(); ++v) {
      AddVisual(*link->VisualByIndex(v), world_from_link, link_name + "::");
    }
  }
  for (uint64_t m = 0; m < model.ModelCount(); ++m) {
    AddModel(*model.ModelByIndex(m), world_from_model, name + "::");
  }
}

sdf::ParserConfig MakeParserConfig(const fs::path& base_dir) {
  sdf::ParserConfig config = sdf::ParserConfig::GlobalConfig();
  // "model://name" and bare relative include URIs resolve beside the world file first.
  config.AddURIPath("model://", base_dir.string());
  for (const char* variable : {"SDF_PATH", "GZ_SIM_RESOURCE_PATH", "IGN_GAZEBO_RESOURCE_PATH"}) {
    if (const char* value = std::getenv(variable)) {
      std::stringstream paths(value);
      std::string path;
      while (std::getline(paths, path, ':')) {
        if (!path.empty()) config.AddURIPath("model://", path);
      }
    }
  }
  config.SetFindCallback([base_dir](const std::string& uri) -> std::string {
    std::string text = uri;
    if (text.rfind("file://", 0) == 0) text = text.substr(7);
    const fs::path candidate = fs::path(text).is_absolute() ? fs::path(text) : base_dir / text;
    std::error_code error;
    return fs::exists(candidate, error) ? candidate.string() : std::string();
  });
  return config;
}

WorldModel BuildWorld(const sdf::Root& root, const sdf::Errors& errors,
                      const std::string& source, const fs::path& base_dir,
                      const fs::path& world_file) {
  if (!errors.empty()) throw InputError(source, "not a readable SDF file: " + FirstError(errors));
  if (root.WorldCount() == 0) throw InputError(source, "no <world> in the SDF file");
  const sdf::World* sdf_world = root.WorldByIndex(0);
  WorldModel world;
  world.world_name = sdf_world->Name();
  Loader loader{source, base_dir, &world, world_file};
  for (uint64_t m = 0; m < sdf_world->ModelCount(); ++m) {
    loader.AddModel(*sdf_world->ModelByIndex(m), Rigid3::Identity(), "");
  }
  for (uint64_t l = 0; l < sdf_world->LightCount(); ++l) {
    const sdf::Light* light = sdf_world->LightByIndex(l);
    if (light->Type() != sdf::LightType::DIRECTIONAL) continue;
    const auto d = light->Direction();
    const Eigen::Vector3d direction =
        ToRigid3(light->RawPose()).rotation * Eigen::Vector3d(d.X(), d.Y(), d.Z());
    if (direction.norm() > 1e-9) world.sun_direction = direction.normalized();
    break;
  }
  return world;
}

// libsdformat prints its errors to stderr as well as returning them; while loading, it is
// kept quiet so that bad input gives the one line of the InputError only.
class QuietSdfConsole {
 public:
  QuietSdfConsole() { sdf::Console::Instance()->SetQuiet(true); }
  ~QuietSdfConsole() { sdf::Console::Instance()->SetQuiet(false); }
};

}  // namespace

WorldModel LoadWorldModel(const std::filesystem::path& sdf_path) {
  const std::string source = sdf_path.string();
  std::error_code error;
  if (!fs::is_regular_file(sdf_path, error)) {
    throw InputError(source, "SDF world file not found");
  }
  const fs::path base_dir = fs::absolute(sdf_path).parent_path();
  sdf::Root root;
  sdf::Errors errors;
  {
    QuietSdfConsole quiet;
    errors = root.Load(sdf_path.string(), MakeParserConfig(base_dir));
  }
  const fs::path world_file = fs::absolute(sdf_path).lexically_normal();
  WorldModel world = BuildWorld(root, errors, source, base_dir, world_file);
  world.sdf_path = world_file;
  return world;
}

WorldModel LoadWorldModelFromString(const std::string& sdf_text,
                                    const std::filesystem::path& base_dir,
                                    const std::string& source) {
  const fs::path dir = fs::absolute(base_dir);
  sdf::Root root;
  sdf::Errors errors;
  {
    QuietSdfConsole quiet;
    errors = root.LoadSdfString(sdf_text, MakeParserConfig(dir));
  }
  return BuildWorld(root, errors, source, dir, fs::path());
}

double DistanceToSurface(const WorldPrimitive& primitive, const Eigen::Vector3d& p_in_world) {
  const Eigen::Vector3d q = primitive.world_from_shape.Inverse() * p_in_world;
  const Eigen::Vector3d half = 0.5 * primitive.size;
  switch (primitive.type) {
    case ShapeType::kBox: {
      const Eigen::Vector3d excess = q.cwiseAbs() - half;
      if ((excess.array() > 0.0).any()) return excess.cwiseMax(0.0).norm();
      return -excess.maxCoeff();  // inside: distance to the nearest face
    }
    case ShapeType::kPlane: {
      const double dx = std::max(std::abs(q.x()) - half.x(), 0.0);
      const double dy = std::max(std::abs(q.y()) - half.y(), 0.0);
      return std::sqrt(dx * dx + dy * dy + q.z() * q.z());
    }
    case ShapeType::kCylinder: {
      const double radial = std::hypot(q.x(), q.y()) - primitive.radius();
      const double axial = std::abs(q.z()) - half.z();
      if (radial > 0.0 || axial > 0.0) {
        return std::hypot(std::max(radial, 0.0), std::max(axial, 0.0));
      }
      return std::min(-radial, -axial);
    }
  }
  return std::numeric_limits<double>::infinity();
}

double DistanceToNearestSurface(const WorldModel& world, const Eigen::Vector3d& p_in_world) {
  double best = std::numeric_limits<double>::infinity();
  for (const WorldPrimitive& primitive : world.primitives) {
    best = std::min(best, DistanceToSurface(primitive, p_in_world));
  }
  return best;
}

}  // namespace arucoslam
