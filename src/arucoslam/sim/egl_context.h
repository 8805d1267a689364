// EglContext: a headless OpenGL 3.3 core context through EGL (Mesa's surfaceless platform,
// a device, or the default display with a pbuffer): no display server needed.
#pragma once

#include <memory>
#include <string>

namespace arucoslam {

class EglContext {
 public:
  // Creates the context and makes it current on the calling thread. Throws
  // std::runtime_error with EGL's error code when no display or context can be made.
  static std::unique_ptr<EglContext> Create();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // Makes the context current on the calling thread (a context is current on one thread).
  void MakeCurrent() const;
  // "platform, GL_RENDERER, GL_VERSION", e.g. "surfaceless, llvmpipe (LLVM 15.0.6, 256 bits),
  // 4.5 (Core Profile) Mesa 22.3.6".
  const std::string& Description() const { return description_; }

 private:
  EglContext() = default;
  void* display_ = nullptr;
  void* surface_ = nullptr;
  void* context_ = nullptr;
  std::string description_;
};

}  // namespace arucoslam
