#include "arucoslam/sim/renderer.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>

#include "arucoslam/sim/egl_context.h"
#include "arucoslam/sim/image_effects.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {
namespace {

// Lighting is evaluated per vertex: the sun term is constant over a flat face (per-surface
// shading), and the headlight varies slowly; the fragment stage only samples the texture,
// which keeps the software rasteriser fast.
constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec3 diffuse;
layout(location = 4) in vec3 ambient;
uniform mat4 clip_from_world;
uniform mat4 cam_from_world;
uniform vec3 sun_direction;
uniform vec3 camera_position;
uniform float ambient_strength;
uniform float sun_strength;
uniform float headlight_strength;
uniform float headlight_range;
uniform float exposure;
out vec2 v_uv;
out vec3 v_light;
out float v_depth;
void main() {
  gl_Position = clip_from_world * vec4(position, 1.0);
  v_uv = uv;
  v_depth = (cam_from_world * vec4(position, 1.0)).z;
  vec3 n = normalize(normal);
  vec3 to_camera = camera_position - position;
  float distance = length(to_camera);
  if (dot(n, to_camera) < 0.0) n = -n;  // two-sided surfaces
  float sun = max(dot(n, -sun_direction), 0.0);
  float head = max(dot(n, to_camera / max(distance, 1e-6)), 0.0) /
               (1.0 + (distance * distance) / (headlight_range * headlight_range));
  v_light = exposure * (ambient_strength * ambient +
                        (sun_strength * sun + headlight_strength * head) * diffuse);
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
in vec2 v_uv;
in vec3 v_light;
in float v_depth;
uniform sampler2D albedo;
uniform int output_depth;
layout(location = 0) out vec4 color;
void main() {
  if (output_depth == 1) {
    color = vec4(v_depth, 0.0, 0.0, 1.0);
    return;
  }
  color = vec4(texture(albedo, v_uv).rgb * v_light, 1.0);
}
)";

GLuint CompileShader(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    throw std::runtime_error(std::string("OpenGL shader does not compile: ") + log);
  }
  return shader;
}

GLuint LinkProgram() {
  const GLuint vertex = CompileShader(GL_VERTEX_SHADER, kVertexShader);
  const GLuint fragment = CompileShader(GL_FRAGMENT_SHADER, kFragmentShader);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vertex);
  glAttachShader(program, fragment);
  glLinkProgram(program);
  glDeleteShader(vertex);
  glDeleteShader(fragment);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(program, sizeof(log), nullptr, log);
    throw std::runtime_error(std::string("OpenGL program does not link: ") + log);
  }
  return program;
}

bool HasGlExtension(const char* name) {
  GLint count = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &count);
  for (GLint i = 0; i < count; ++i) {
    const auto* extension = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, i));
    if (extension != nullptr && std::string(extension) == name) return true;
  }
  return false;
}

// Uploads an 8-bit BGR image as a mipmapped, trilinear (and anisotropic) texture.
GLuint UploadTexture(const cv::Mat& bgr, double max_anisotropy) {
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  const cv::Mat contiguous = bgr.isContinuous() ? bgr : bgr.clone();
  // Row 0 of the image (its top) is texture coordinate t = 0, as the SDF subset says v.
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, contiguous.cols, contiguous.rows, 0, GL_BGR,
               GL_UNSIGNED_BYTE, contiguous.data);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (max_anisotropy > 1.0 && (HasGlExtension("GL_ARB_texture_filter_anisotropic") ||
                               HasGlExtension("GL_EXT_texture_filter_anisotropic"))) {
    GLfloat supported = 1.0f;
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &supported);
    glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY,
                    std::min<GLfloat>(supported, static_cast<GLfloat>(max_anisotropy)));
  }
  return texture;
}

// A framebuffer with one colour renderbuffer and a depth renderbuffer.
struct Framebuffer {
  GLuint framebuffer = 0;
  GLuint color = 0;
  GLuint depth = 0;

  void Create(int width, int height, int samples, GLenum color_format) {
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glGenRenderbuffers(1, &color);
    glBindRenderbuffer(GL_RENDERBUFFER, color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, color_format, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width,
                                     height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("OpenGL framebuffer incomplete");
    }
  }
  void Destroy() {
    if (framebuffer != 0) glDeleteFramebuffers(1, &framebuffer);
    if (color != 0) glDeleteRenderbuffers(1, &color);
    if (depth != 0) glDeleteRenderbuffers(1, &depth);
    framebuffer = color = depth = 0;
  }
};

// ---- World primitives to triangles (world coordinates), grouped by texture. ----

struct SceneVertex {
  float position[3];
  float normal[3];
  float uv[2];
  float diffuse[3];
  float ambient[3];
};

// The vertices of one primitive and its bounding sphere (world frame), for culling.
struct PrimitiveRange {
  GLint first_vertex = 0;
  GLsizei vertex_count = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;
};

struct SceneBatch {
  std::filesystem::path texture;  // empty: untextured (a white texel)
  std::vector<PrimitiveRange> ranges;
};

struct SceneMesh {
  std::vector<SceneVertex> vertices;
  std::vector<SceneBatch> batches;
};

// Segments around a cylinder: enough that the polygon deviates from the circle by at most
// about 2 mm (r (1 - cos(pi / n))), between 12 and 48.
int CylinderSegments(double radius) {
  const int n = static_cast<int>(std::ceil(M_PI / std::acos(1.0 - std::min(0.002 / radius, 1.0))));
  return std::clamp(n, 12, 48);
}

// Appends the triangles of one primitive (in its shape frame) to `out`.
class PrimitiveTessellator {
 public:
  PrimitiveTessellator(const WorldPrimitive& primitive, std::vector<SceneVertex>* out)
      : primitive_(primitive), out_(out) {}

  // A rectangle with centre `centre`, unit axes `right` and `up` (image right and up of
  // the texture), half sizes; u runs 0..1 along right, v 0..1 from top to bottom.
  void Quad(const Eigen::Vector3d& centre, const Eigen::Vector3d& right,
            const Eigen::Vector3d& up, double half_right, double half_up) {
    const Eigen::Vector3d normal = right.cross(up);
    const Eigen::Vector3d corners[4] = {
        centre - half_right * right + half_up * up, centre + half_right * right + half_up * up,
        centre + half_right * right - half_up * up, centre - half_right * right - half_up * up};
    const Eigen::Vector2d uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int index : {0, 1, 2, 0, 2, 3}) Vertex(corners[index], normal, uvs[index]);
  }

  void Box() {
    const Eigen::Vector3d h = 0.5 * primitive_.size;
    const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                          z = Eigen::Vector3d::UnitZ();
    Quad(h.z() * z, x, y, h.x(), h.y());     // +z: right +x, up +y
    Quad(-h.z() * z, -x, y, h.x(), h.y());   // -z: right -x, up +y
    Quad(h.x() * x, y, z, h.y(), h.z());     // +x: right +y, up +z
    Quad(-h.x() * x, -y, z, h.y(), h.z());   // -x: right -y, up +z
    Quad(h.y() * y, -x, z, h.x(), h.z());    // +y: right -x, up +z
    Quad(-h.y() * y, x, z, h.x(), h.z());    // -y: right +x, up +z
  }

  void Plane() {
    Quad(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
         0.5 * primitive_.size.x(), 0.5 * primitive_.size.y());
  }

  void Cylinder() {
    const double r = primitive_.radius(), half = 0.5 * primitive_.size.z();
    const int segments = CylinderSegments(r);
    for (int i = 0; i < segments; ++i) {
      const double u0 = static_cast<double>(i) / segments;
      const double u1 = static_cast<double>(i + 1) / segments;
      const Eigen::Vector3d n0(std::cos(2 * M_PI * u0), std::sin(2 * M_PI * u0), 0);
      const Eigen::Vector3d n1(std::cos(2 * M_PI * u1), std::sin(2 * M_PI * u1), 0);
      const Eigen::Vector3d top(0, 0, half), bottom(0, 0, -half);
      // Side: u around the axis, v from the top (0) to the bottom (1).
      Vertex(r * n0 + top, n0, {u0, 0});
      Vertex(r * n0 + bottom, n0, {u0, 1});
      Vertex(r * n1 + bottom, n1, {u1, 1});
      Vertex(r * n0 + top, n0, {u0, 0});
      Vertex(r * n1 + bottom, n1, {u1, 1});
      Vertex(r * n1 + top, n1, {u1, 0});
      // Caps, mapped like a box's +z / -z face of side 2r.
      for (const double sign : {1.0, -1.0}) {
        const Eigen::Vector3d centre(0, 0, sign * half);
        const Eigen::Vector3d normal(0, 0, sign);
        auto cap_uv = [&](const Eigen::Vector3d& n) {
          return Eigen::Vector2d(0.5 + 0.5 * sign * n.x(), 0.5 - 0.5 * n.y());
        };
        Vertex(centre, normal, {0.5, 0.5});
        Vertex(centre + r * n0, normal, cap_uv(n0));
        Vertex(centre + r * n1, normal, cap_uv(n1));
      }
    }
  }

 private:
  void Vertex(const Eigen::Vector3d& p_in_shape, const Eigen::Vector3d& n_in_shape,
              const Eigen::Vector2d& uv) {
    const Eigen::Vector3d p = primitive_.world_from_shape * p_in_shape;
    const Eigen::Vector3d n = primitive_.world_from_shape.rotation * n_in_shape;
    SceneVertex vertex{};
    for (int k = 0; k < 3; ++k) {
      vertex.position[k] = static_cast<float>(p[k]);
      vertex.normal[k] = static_cast<float>(n[k]);
      vertex.diffuse[k] = static_cast<float>(primitive_.diffuse[k]);
      vertex.ambient[k] = static_cast<float>(primitive_.ambient[k]);
    }
    vertex.uv[0] = static_cast<float>(uv.x());
    vertex.uv[1] = static_cast<float>(uv.y());
    out_->push_back(vertex);
  }

  const WorldPrimitive& primitive_;
  std::vector<SceneVertex>* out_;
};

SceneMesh BuildSceneMesh(const WorldModel& world) {
  std::map<std::filesystem::path, std::pair<std::vector<SceneVertex>, SceneBatch>> by_texture;
  for (const WorldPrimitive& primitive : world.primitives) {
    auto& [vertices, batch] = by_texture[primitive.texture];
    PrimitiveRange range;
    range.first_vertex = static_cast<GLint>(vertices.size());
    PrimitiveTessellator tessellator(primitive, &vertices);
    switch (primitive.type) {
      case ShapeType::kBox: tessellator.Box(); break;
      case ShapeType::kPlane: tessellator.Plane(); break;
      case ShapeType::kCylinder: tessellator.Cylinder(); break;
    }
    range.vertex_count = static_cast<GLsizei>(vertices.size()) - range.first_vertex;
    range.centre = primitive.world_from_shape.translation;
    range.radius = 0.5 * primitive.size.norm() + 1e-3;
    batch.ranges.push_back(range);
  }
  SceneMesh mesh;
  for (auto& [texture, entry] : by_texture) {
    auto& [vertices, batch] = entry;
    batch.texture = texture;
    for (PrimitiveRange& range : batch.ranges) {
      range.first_vertex += static_cast<GLint>(mesh.vertices.size());
    }
    mesh.batches.push_back(std::move(batch));
    mesh.vertices.insert(mesh.vertices.end(), vertices.begin(), vertices.end());
  }
  return mesh;
}

Eigen::Matrix4f ToFloat(const Eigen::Matrix4d& matrix) { return matrix.cast<float>(); }

}  // namespace

bool RenderOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.InRange("msaa_samples", msaa_samples, 1, 16, Interval::kClosed);
  check.AtLeast("max_anisotropy", max_anisotropy, 1.0);
  check.AtLeast("ambient", ambient, 0.0);
  check.AtLeast("sun", sun, 0.0);
  check.AtLeast("headlight", headlight, 0.0);
  check.Above("headlight_range_m", headlight_range_m, 0.0);
  check.Above("near_m", near_m, 0.0);
  check.Above("far_m", far_m, near_m, "near_m");
  check.Above("exposure_gain", exposure_gain, 0.0);
  check.InRange("exposure_variation", exposure_variation, 0.0, 1.0, Interval::kClosedOpen);
  check.Above("exposure_period_s", exposure_period_s, 0.0);
  check.AtLeast("noise_sigma", noise_sigma, 0.0);
  check.InRange("distortion_oversampling", distortion_oversampling, 1.0, 4.0, Interval::kClosed);
  check.Require((background.array() >= 0.0).all() && (background.array() <= 1.0).all(),
                "background", "in [0, 1] in every channel");
  return check.ok();
}

Eigen::Matrix4d ClipFromCamera(double fx, double fy, double cx, double cy, int width,
                               int height, double near_m, double far_m) {
  // Window x = (ndc_x + 1) / 2 * width must be u + 0.5 with u = fx x / z + cx; the same
  // for rows (window y = v + 0.5, so glReadPixels' first row is the image's top row).
  Eigen::Matrix4d clip_from_cam = Eigen::Matrix4d::Zero();
  clip_from_cam(0, 0) = 2.0 * fx / width;
  clip_from_cam(0, 2) = 2.0 * (cx + 0.5) / width - 1.0;
  clip_from_cam(1, 1) = 2.0 * fy / height;
  clip_from_cam(1, 2) = 2.0 * (cy + 0.5) / height - 1.0;
  clip_from_cam(2, 2) = (far_m + near_m) / (far_m - near_m);
  clip_from_cam(2, 3) = -2.0 * far_m * near_m / (far_m - near_m);
  clip_from_cam(3, 2) = 1.0;
  return clip_from_cam;
}

class Renderer::Impl {
 public:
  Impl(const WorldModel& world, const CameraModel& camera, const RenderOptions& options);
  ~Impl();
  cv::Mat DrawColor(const Rigid3& world_from_cam, double gain);  // CV_8UC4 BGRA, pinhole
  cv::Mat DrawDepth(const Rigid3& world_from_cam);                // CV_32FC1, pinhole
  RenderedFrame Finish(const cv::Mat& accumulated_bgra, int count, const Rigid3& middle,
                       std::uint64_t frame_index);

  CameraModel camera;          // the output camera
  CameraModel pinhole;         // what OpenGL renders (the camera itself when undistorted)
  std::optional<DistortionRemap> remap;
  RenderOptions options;
  Eigen::Vector3d sun_direction;
  std::unique_ptr<EglContext> context;

 private:
  void Draw(const Rigid3& world_from_cam, double gain, bool depth_pass);

  GLuint program_ = 0;
  GLuint vertex_array_ = 0;
  GLuint vertex_buffer_ = 0;
  std::vector<SceneBatch> batches_;       // one per texture, drawn in order
  std::vector<GLuint> textures_;          // parallel to batches_
  Framebuffer multisample_;               // MSAA colour target
  Framebuffer resolved_;                  // single-sample colour target (read back)
  Framebuffer depth_target_;              // single-sample R32F depth target
};

Renderer::Impl::Impl(const WorldModel& world, const CameraModel& camera_in,
                     const RenderOptions& options_in)
    : camera(camera_in), pinhole(camera_in), options(options_in),
      sun_direction(world.sun_direction.normalized()) {
  if (!options.Check()) throw std::invalid_argument("RenderOptions::Check failed");
  if (!camera.Check()) throw std::invalid_argument("CameraModel::Check failed");
  if (camera.model != DistortionModel::kNone) {
    remap.emplace(camera, options.distortion_oversampling);
    pinhole = remap->pinhole();
  }
  SceneMesh mesh = BuildSceneMesh(world);
  context = EglContext::Create();
  program_ = LinkProgram();
  glGenVertexArrays(1, &vertex_array_);
  glBindVertexArray(vertex_array_);
  glGenBuffers(1, &vertex_buffer_);
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_);
  glBufferData(GL_ARRAY_BUFFER, mesh.vertices.size() * sizeof(SceneVertex),
               mesh.vertices.data(), GL_STATIC_DRAW);
  const GLsizei stride = sizeof(SceneVertex);
  const std::pair<int, std::size_t> attributes[] = {
      {3, offsetof(SceneVertex, position)}, {3, offsetof(SceneVertex, normal)},
      {2, offsetof(SceneVertex, uv)},       {3, offsetof(SceneVertex, diffuse)},
      {3, offsetof(SceneVertex, ambient)}};
  for (GLuint i = 0; i < 5; ++i) {
    glEnableVertexAttribArray(i);
    glVertexAttribPointer(i, attributes[i].first, GL_FLOAT, GL_FALSE, stride,
                          reinterpret_cast<const void*>(attributes[i].second));
  }
  batches_ = std::move(mesh.batches);
  for (const SceneBatch& batch : batches_) {
    cv::Mat image;
    if (batch.texture.empty()) {
      image = cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(255));
    } else {
      image = cv::imread(batch.texture.string(), cv::IMREAD_COLOR);
      if (image.empty()) throw InputError(batch.texture.string(), "cannot decode the texture");
    }
    textures_.push_back(UploadTexture(image, options.max_anisotropy));
  }
  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  const int samples = std::min(options.msaa_samples, static_cast<int>(max_samples));
  if (samples > 1) multisample_.Create(pinhole.width, pinhole.height, samples, GL_RGBA8);
  resolved_.Create(pinhole.width, pinhole.height, 0, GL_RGBA8);
  if (options.depth) depth_target_.Create(pinhole.width, pinhole.height, 0, GL_R32F);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
}

Renderer::Impl::~Impl() {
  if (context == nullptr) return;
  context->MakeCurrent();
  if (!textures_.empty()) glDeleteTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
  glDeleteBuffers(1, &vertex_buffer_);
  glDeleteVertexArrays(1, &vertex_array_);
  glDeleteProgram(program_);
  multisample_.Destroy();
  resolved_.Destroy();
  depth_target_.Destroy();
}

void Renderer::Impl::Draw(const Rigid3& world_from_cam, double gain, bool depth_pass) {
  const Eigen::Matrix4d cam_from_world = world_from_cam.Inverse().ToMatrix();
  const Eigen::Matrix4d clip_from_world =
      ClipFromCamera(pinhole.fx, pinhole.fy, pinhole.cx, pinhole.cy, pinhole.width,
                     pinhole.height, options.near_m, options.far_m) *
      cam_from_world;
  glViewport(0, 0, pinhole.width, pinhole.height);
  if (depth_pass) {
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  } else {
    const Eigen::Vector3d background = options.background * gain;
    glClearColor(background.x(), background.y(), background.z(), 1.0f);
  }
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glUseProgram(program_);
  auto location = [this](const char* name) { return glGetUniformLocation(program_, name); };
  glUniformMatrix4fv(location("clip_from_world"), 1, GL_FALSE, ToFloat(clip_from_world).data());
  glUniformMatrix4fv(location("cam_from_world"), 1, GL_FALSE, ToFloat(cam_from_world).data());
  const Eigen::Vector3f sun = sun_direction.cast<float>();
  const Eigen::Vector3f position = world_from_cam.translation.cast<float>();
  glUniform3f(location("sun_direction"), sun.x(), sun.y(), sun.z());
  glUniform3f(location("camera_position"), position.x(), position.y(), position.z());
  glUniform1f(location("ambient_strength"), options.ambient);
  glUniform1f(location("sun_strength"), options.sun);
  glUniform1f(location("headlight_strength"), options.headlight);
  glUniform1f(location("headlight_range"), options.headlight_range_m);
  glUniform1f(location("exposure"), gain);
  glUniform1i(location("output_depth"), depth_pass ? 1 : 0);
  glUniform1i(location("albedo"), 0);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(vertex_array_);
  // Frustum culling by bounding spheres: the side planes of the pinhole's view (through
  // the camera centre, normals pointing inwards) and the near plane, in the camera frame.
  const double left = (-0.5 - pinhole.cx) / pinhole.fx;
  const double right = (pinhole.width - 0.5 - pinhole.cx) / pinhole.fx;
  const double top = (-0.5 - pinhole.cy) / pinhole.fy;
  const double bottom = (pinhole.height - 0.5 - pinhole.cy) / pinhole.fy;
  const Eigen::Vector3d planes[4] = {Eigen::Vector3d(1, 0, -left).normalized(),
                                     Eigen::Vector3d(-1, 0, right).normalized(),
                                     Eigen::Vector3d(0, 1, -top).normalized(),
                                     Eigen::Vector3d(0, -1, bottom).normalized()};
  const Rigid3 cam_from_world_rigid = world_from_cam.Inverse();
  std::vector<GLint> firsts;
  std::vector<GLsizei> counts;
  for (std::size_t i = 0; i < batches_.size(); ++i) {
    firsts.clear();
    counts.clear();
    for (const PrimitiveRange& range : batches_[i].ranges) {
      const Eigen::Vector3d centre = cam_from_world_rigid * range.centre;
      bool visible = centre.z() + range.radius > options.near_m &&
                     centre.z() - range.radius < options.far_m;
      for (int k = 0; k < 4 && visible; ++k) visible = planes[k].dot(centre) > -range.radius;
      if (!visible && options.frustum_culling) continue;
      firsts.push_back(range.first_vertex);
      counts.push_back(range.vertex_count);
    }
    if (firsts.empty()) continue;
    glBindTexture(GL_TEXTURE_2D, textures_[i]);
    glMultiDrawArrays(GL_TRIANGLES, firsts.data(), counts.data(),
                      static_cast<GLsizei>(firsts.size()));
  }
}

cv::Mat Renderer::Impl::DrawColor(const Rigid3& world_from_cam, double gain) {
  const bool multisampled = multisample_.framebuffer != 0;
  glBindFramebuffer(GL_FRAMEBUFFER,
                    multisampled ? multisample_.framebuffer : resolved_.framebuffer);
  Draw(world_from_cam, gain, false);
  if (multisampled) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, multisample_.framebuffer);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolved_.framebuffer);
    glBlitFramebuffer(0, 0, pinhole.width, pinhole.height, 0, 0, pinhole.width,
                      pinhole.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolved_.framebuffer);
  cv::Mat bgra(pinhole.height, pinhole.width, CV_8UC4);
  glReadPixels(0, 0, pinhole.width, pinhole.height, GL_BGRA, GL_UNSIGNED_BYTE, bgra.data);
  return bgra;
}

cv::Mat Renderer::Impl::DrawDepth(const Rigid3& world_from_cam) {
  glBindFramebuffer(GL_FRAMEBUFFER, depth_target_.framebuffer);
  Draw(world_from_cam, 1.0, true);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, depth_target_.framebuffer);
  cv::Mat depth(pinhole.height, pinhole.width, CV_32FC1);
  glReadPixels(0, 0, pinhole.width, pinhole.height, GL_RED, GL_FLOAT, depth.data);
  return depth;
}

RenderedFrame Renderer::Impl::Finish(const cv::Mat& accumulated_bgra, int count,
                                     const Rigid3& middle, std::uint64_t frame_index) {
  // accumulated_bgra: CV_8UC4 for one render, CV_32FC4 (sum) for several.
  cv::Mat bgr;
  cv::cvtColor(accumulated_bgra, bgr, cv::COLOR_BGRA2BGR);
  if (count > 1) bgr.convertTo(bgr, CV_32FC3, 1.0 / count);
  if (remap) bgr = remap->Apply(bgr, cv::INTER_LINEAR, 255.0 * options.background.x());
  RenderedFrame frame;
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  const bool exact_bytes = options.noise_sigma == 0.0 && grey.depth() == CV_8U;
  frame.grey = exact_bytes ? grey
                           : AddNoiseAndQuantize(grey, options.noise_sigma, options.noise_seed,
                                                 frame_index);
  if (options.rgb) {
    frame.rgb = (options.noise_sigma == 0.0 && bgr.depth() == CV_8U)
                    ? bgr
                    : AddNoiseAndQuantize(bgr, options.noise_sigma, options.noise_seed + 1,
                                          frame_index);
  }
  if (options.depth) {
    frame.depth = DrawDepth(middle);
    if (remap) frame.depth = remap->Apply(frame.depth, cv::INTER_NEAREST, 0.0);
  }
  return frame;
}

Renderer::Renderer(const WorldModel& world, const CameraModel& camera,
                   const RenderOptions& options)
    : impl_(std::make_unique<Impl>(world, camera, options)) {}

Renderer::~Renderer() = default;

RenderedFrame Renderer::Render(const Rigid3& world_from_cam, std::uint64_t frame_index,
                               double time_s) {
  return Render(std::vector<Rigid3>{world_from_cam}, frame_index, time_s);
}

RenderedFrame Renderer::Render(const std::vector<Rigid3>& world_from_cam_during_exposure,
                               std::uint64_t frame_index, double time_s) {
  if (world_from_cam_during_exposure.empty()) {
    throw std::invalid_argument("Renderer::Render: no pose");
  }
  impl_->context->MakeCurrent();
  const RenderOptions& options = impl_->options;
  const double gain = ExposureGainAt(options.exposure_gain, options.exposure_variation,
                                     options.exposure_period_s, time_s);
  const int count = static_cast<int>(world_from_cam_during_exposure.size());
  cv::Mat accumulated;
  if (count == 1) {
    accumulated = impl_->DrawColor(world_from_cam_during_exposure.front(), gain);
  } else {
    accumulated = cv::Mat::zeros(impl_->pinhole.height, impl_->pinhole.width, CV_32FC4);
    for (const Rigid3& pose : world_from_cam_during_exposure) {
      cv::accumulate(impl_->DrawColor(pose, gain), accumulated);
    }
  }
  return impl_->Finish(accumulated, count, world_from_cam_during_exposure[count / 2],
                       frame_index);
}

const CameraModel& Renderer::camera() const { return impl_->camera; }

std::string Renderer::ContextDescription() const { return impl_->context->Description(); }

}  // namespace arucoslam
