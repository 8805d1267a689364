#include "arucoslam/sim/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <cstring>
#include <stdexcept>

#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

std::string EglErrorText(const char* what) {
  char code[16];
  std::snprintf(code, sizeof(code), "0x%04x", static_cast<unsigned>(eglGetError()));
  return std::string("EGL: ") + what + " failed (error " + code + ")";
}

bool HasExtension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const std::size_t length = std::strlen(name);
  for (const char* p = std::strstr(extensions, name); p != nullptr;
       p = std::strstr(p + length, name)) {
    const bool starts = p == extensions || p[-1] == ' ';
    const bool ends = p[length] == '\0' || p[length] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

// Tries the surfaceless platform, then the first EGL device, then the default display.
EGLDisplay OpenDisplay(std::string* platform_name) {
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display != nullptr &&
      HasExtension(client_extensions, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay display =
        get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display != EGL_NO_DISPLAY && eglInitialize(display, nullptr, nullptr)) {
      *platform_name = "surfaceless";
      return display;
    }
  }
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(
      eglGetProcAddress("eglQueryDevicesEXT"));
  if (get_platform_display != nullptr && query_devices != nullptr &&
      HasExtension(client_extensions, "EGL_EXT_platform_device")) {
    EGLDeviceEXT devices[4];
    EGLint count = 0;
    if (query_devices(4, devices, &count) && count > 0) {
      EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
      if (display != EGL_NO_DISPLAY && eglInitialize(display, nullptr, nullptr)) {
        *platform_name = "device";
        return display;
      }
    }
  }
  EGLDisplay display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, nullptr, nullptr)) {
    throw std::runtime_error(EglErrorText("eglInitialize (no usable display)"));
  }
  *platform_name = "default display";
  return display;
}

}  // namespace

std::unique_ptr<EglContext> EglContext::Create() {
  std::unique_ptr<EglContext> result(new EglContext());
  std::string platform;
  EGLDisplay display = OpenDisplay(&platform);
  result->display_ = display;
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                      EGL_OPENGL_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8,
                                      EGL_BLUE_SIZE, 8, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  if (!eglChooseConfig(display, config_attributes, &config, 1, &num_configs) ||
      num_configs == 0) {
    // The surfaceless platform may offer no pbuffer configs; any GL config will do.
    const EGLint any_attributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    if (!eglChooseConfig(display, any_attributes, &config, 1, &num_configs) ||
        num_configs == 0) {
      throw std::runtime_error(EglErrorText("eglChooseConfig"));
    }
  }
  if (!eglBindAPI(EGL_OPENGL_API)) throw std::runtime_error(EglErrorText("eglBindAPI"));
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION,
                                       3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  result->context_ = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
  if (result->context_ == EGL_NO_CONTEXT) {
    throw std::runtime_error(EglErrorText("eglCreateContext (OpenGL 3.3 core)"));
  }
  const char* display_extensions = eglQueryString(display, EGL_EXTENSIONS);
  if (!HasExtension(display_extensions, "EGL_KHR_surfaceless_context")) {
    const EGLint pbuffer_attributes[] = {EGL_WIDTH, 16, EGL_HEIGHT, 16, EGL_NONE};
    result->surface_ = eglCreatePbufferSurface(display, config, pbuffer_attributes);
    if (result->surface_ == EGL_NO_SURFACE) {
      throw std::runtime_error(EglErrorText("eglCreatePbufferSurface"));
    }
  }
  result->MakeCurrent();
  result->description_ = platform + ", " +
                         reinterpret_cast<const char*>(glGetString(GL_RENDERER)) + ", " +
                         reinterpret_cast<const char*>(glGetString(GL_VERSION));
  ARUCOSLAM_LOG_DEBUG("OpenGL context: {}", result->description_);
  return result;
}

void EglContext::MakeCurrent() const {
  EGLSurface surface = surface_ == nullptr ? EGL_NO_SURFACE : surface_;
  if (!eglMakeCurrent(display_, surface, surface, context_)) {
    throw std::runtime_error(EglErrorText("eglMakeCurrent"));
  }
}

EglContext::~EglContext() {
  if (display_ == nullptr) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_ != nullptr) eglDestroySurface(display_, surface_);
  if (context_ != nullptr) eglDestroyContext(display_, context_);
  // The display stays initialised: other contexts of this process may share it.
}

}  // namespace arucoslam
