// Offscreen OpenGL contexts for headless rendering: EGL (surfaceless or device platform) and
// OSMesa, each loaded at run time with dlopen.
//
// One GL platform library per process: MuJoCo 2.2's mjr_makeContext looks for
// eglGetProcAddress, then OSMesaGetProcAddress, then glXGetProcAddressARB among every loaded
// library (the global scope first, then each loaded object, so RTLD_LOCAL does not hide one) and
// loads GL through the first it finds. With libEGL and libOSMesa both in a process, OSMesa
// contexts get EGL's function pointers and mjr_makeContext fails ("gladLoadGL error"). So no
// Wrap binary links either library: the chosen backend is dlopen'ed (RTLD_GLOBAL) when the
// first context is made, and asking for the other one later in the same process fails cleanly.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "core/result.h"

namespace wrap::render {

/// Which offscreen GL platform to use.
enum class GlBackend {
  kEgl,     ///< EGL: Mesa's surfaceless platform, else the device platform (NVIDIA), else the
            ///< default display. Needs no DISPLAY. The default.
  kOsmesa,  ///< OSMesa: Mesa's software renderer into client memory. Needs no DISPLAY.
};

/// "egl" or "osmesa".
std::string_view ToString(GlBackend backend);

/// Parses "egl" or "osmesa" (exactly); kInvalidInput naming the choices otherwise.
Result<GlBackend> ParseGlBackend(std::string_view name);

/// An offscreen GL context (compatibility profile, as MuJoCo 2.2's fixed-function renderer
/// needs), current on the thread that created it until destroyed.
class GlContext {
 public:
  /// Loads the backend's library (once per process) and makes a context current on this thread.
  /// Fails with kInvalidInput when the backend is unavailable: the library is missing, the other
  /// backend is already loaded in this process, or no display/config/context could be made; the
  /// message names every attempt and why it failed.
  static Result<std::unique_ptr<GlContext>> Create(GlBackend backend);

  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  /// The backend this context uses.
  GlBackend backend() const { return backend_; }
  /// What was made, e.g. "EGL 1.5, surfaceless platform; GL 4.5 (Compatibility Profile) Mesa
  /// 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& description() const { return description_; }
  /// Makes this context current on the calling thread again. Fails with kInternal.
  virtual Result<void> MakeCurrent() = 0;

 protected:
  explicit GlContext(GlBackend backend) : backend_(backend) {}
  GlBackend backend_;
  std::string description_;
};

}  // namespace wrap::render
