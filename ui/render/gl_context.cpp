#include "render/gl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <dlfcn.h>

#include <mutex>
#include <vector>

namespace wrap::render {

namespace {

// The libraries of each backend, by preference. Only the first that loads is used.
constexpr const char* kEglLibraries[] = {"libEGL.so.1", "libEGL.so"};
constexpr const char* kOsmesaLibraries[] = {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"};

// Size of OSMesa's own colour buffer: MuJoCo draws into its offscreen framebuffer object, so
// the context's default buffer is never read [px].
constexpr int kOsmesaBufferSize = 16;

bool AnyLoaded(std::initializer_list<const char*> names) {
  for (const char* n : names) {
    if (void* h = dlopen(n, RTLD_LAZY | RTLD_NOLOAD)) {
      dlclose(h);
      return true;
    }
  }
  return false;
}

bool EglLoaded() { return AnyLoaded({"libEGL.so.1", "libEGL.so"}); }
bool OsmesaLoaded() { return AnyLoaded({"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}); }

// Opens the first library that loads, RTLD_GLOBAL so MuJoCo finds its get-proc-address function
// in the global scope. The handle is never closed: MuJoCo keeps the GL pointers it loaded.
template <size_t N>
Result<void*> OpenLibrary(const char* const (&names)[N], const char* backend) {
  std::string tried;
  for (const char* name : names) {
    if (void* h = dlopen(name, RTLD_NOW | RTLD_GLOBAL)) return h;
    const char* why = dlerror();
    tried += std::string(tried.empty() ? "" : "; ") + (why ? why : name);
  }
  return Fail(ErrorCode::kInvalidInput, std::string(backend) + ": cannot load the library (" +
                                            tried + "); install it or choose another --backend");
}

// The other backend's library in this process makes MuJoCo load GL through the wrong one.
Result<void> CheckExclusive(GlBackend backend) {
  const bool conflict = backend == GlBackend::kEgl ? OsmesaLoaded() : EglLoaded();
  if (!conflict) return {};
  const char* other = backend == GlBackend::kEgl ? "OSMesa" : "EGL";
  return Fail(ErrorCode::kInvalidInput,
              std::string(backend == GlBackend::kEgl ? "EGL" : "OSMesa") + ": " + other +
                  " is already loaded in this process, and MuJoCo would load GL through it; use "
                  "one GL backend per process (run another process for the other backend)");
}

using GetStringFn = const unsigned char* (*)(unsigned int);

std::string GlStrings(GetStringFn get_string) {
  if (!get_string) return "";
  auto str = [&](unsigned int name) {
    const unsigned char* s = get_string(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return "GL " + str(GL_VERSION) + ", " + str(GL_RENDERER);
}

// ---------------------------------------------------------------------------------------------
// EGL

struct EglApi {
  void* lib = nullptr;
  PFNEGLGETPROCADDRESSPROC GetProcAddress = nullptr;
  PFNEGLGETERRORPROC GetError = nullptr;
  PFNEGLQUERYSTRINGPROC QueryString = nullptr;
  PFNEGLGETDISPLAYPROC GetDisplay = nullptr;
  PFNEGLINITIALIZEPROC Initialize = nullptr;
  PFNEGLTERMINATEPROC Terminate = nullptr;
  PFNEGLCHOOSECONFIGPROC ChooseConfig = nullptr;
  PFNEGLBINDAPIPROC BindAPI = nullptr;
  PFNEGLCREATECONTEXTPROC CreateContext = nullptr;
  PFNEGLDESTROYCONTEXTPROC DestroyContext = nullptr;
  PFNEGLCREATEPBUFFERSURFACEPROC CreatePbufferSurface = nullptr;
  PFNEGLDESTROYSURFACEPROC DestroySurface = nullptr;
  PFNEGLMAKECURRENTPROC MakeCurrent = nullptr;
  PFNEGLGETPLATFORMDISPLAYEXTPROC GetPlatformDisplayEXT = nullptr;
  PFNEGLQUERYDEVICESEXTPROC QueryDevicesEXT = nullptr;
};

template <typename F>
void Load(void* lib, F& fn, const char* name) {
  fn = reinterpret_cast<F>(dlsym(lib, name));
}

Result<const EglApi*> LoadEgl() {
  static std::mutex mutex;
  static EglApi api;
  std::lock_guard lock(mutex);
  if (api.lib) return &api;
  if (auto ok = CheckExclusive(GlBackend::kEgl); !ok) return std::unexpected(ok.error());
  auto lib = OpenLibrary(kEglLibraries, "EGL");
  if (!lib) return std::unexpected(lib.error());
  EglApi a;
  a.lib = *lib;
  Load(a.lib, a.GetProcAddress, "eglGetProcAddress");
  Load(a.lib, a.GetError, "eglGetError");
  Load(a.lib, a.QueryString, "eglQueryString");
  Load(a.lib, a.GetDisplay, "eglGetDisplay");
  Load(a.lib, a.Initialize, "eglInitialize");
  Load(a.lib, a.Terminate, "eglTerminate");
  Load(a.lib, a.ChooseConfig, "eglChooseConfig");
  Load(a.lib, a.BindAPI, "eglBindAPI");
  Load(a.lib, a.CreateContext, "eglCreateContext");
  Load(a.lib, a.DestroyContext, "eglDestroyContext");
  Load(a.lib, a.CreatePbufferSurface, "eglCreatePbufferSurface");
  Load(a.lib, a.DestroySurface, "eglDestroySurface");
  Load(a.lib, a.MakeCurrent, "eglMakeCurrent");
  if (!a.GetProcAddress || !a.GetError || !a.QueryString || !a.GetDisplay || !a.Initialize ||
      !a.Terminate || !a.ChooseConfig || !a.BindAPI || !a.CreateContext || !a.DestroyContext ||
      !a.CreatePbufferSurface || !a.DestroySurface || !a.MakeCurrent) {
    return Fail(ErrorCode::kInvalidInput, "EGL: the library lacks EGL 1.4 core functions");
  }
  a.GetPlatformDisplayEXT = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      a.GetProcAddress("eglGetPlatformDisplayEXT"));
  a.QueryDevicesEXT =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(a.GetProcAddress("eglQueryDevicesEXT"));
  api = a;
  return &api;
}

std::string EglErrorName(EGLint e) {
  switch (e) {
    case EGL_SUCCESS:
      return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED:
      return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS:
      return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC:
      return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE:
      return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG:
      return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT:
      return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY:
      return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH:
      return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER:
      return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE:
      return "EGL_BAD_SURFACE";
    default: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "EGL error 0x%x", e);
      return buf;
    }
  }
}

bool HasExtension(const char* list, std::string_view ext) {
  if (!list) return false;
  const std::string_view all(list);
  size_t pos = 0;
  while ((pos = all.find(ext, pos)) != std::string_view::npos) {
    const size_t end = pos + ext.size();
    if ((pos == 0 || all[pos - 1] == ' ') && (end == all.size() || all[end] == ' ')) return true;
    pos = end;
  }
  return false;
}

class EglContext final : public GlContext {
 public:
  EglContext() : GlContext(GlBackend::kEgl) {}
  ~EglContext() override {
    if (!api_) return;
    if (display_ != EGL_NO_DISPLAY) {
      api_->MakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      if (surface_ != EGL_NO_SURFACE) api_->DestroySurface(display_, surface_);
      if (context_ != EGL_NO_CONTEXT) api_->DestroyContext(display_, context_);
    }
  }

  Result<void> MakeCurrent() override {
    if (!api_->MakeCurrent(display_, surface_, surface_, context_)) {
      return Fail(ErrorCode::kInternal,
                  "EGL: eglMakeCurrent failed: " + EglErrorName(api_->GetError()));
    }
    return {};
  }

  // Tries to make a context on `display`; on failure returns why (and leaves nothing behind).
  std::string TryDisplay(const EglApi* api, EGLDisplay display, const std::string& label) {
    api_ = api;
    if (display == EGL_NO_DISPLAY) return "no display (" + EglErrorName(api->GetError()) + ")";
    EGLint major = 0, minor = 0;
    if (!api->Initialize(display, &major, &minor)) {
      return "eglInitialize failed (" + EglErrorName(api->GetError()) + ")";
    }
    const EGLint attribs[] = {EGL_SURFACE_TYPE,
                              EGL_PBUFFER_BIT,
                              EGL_RENDERABLE_TYPE,
                              EGL_OPENGL_BIT,
                              EGL_RED_SIZE,
                              8,
                              EGL_GREEN_SIZE,
                              8,
                              EGL_BLUE_SIZE,
                              8,
                              EGL_ALPHA_SIZE,
                              8,
                              EGL_DEPTH_SIZE,
                              24,
                              EGL_STENCIL_SIZE,
                              8,
                              EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!api->ChooseConfig(display, attribs, &config, 1, &count) || count < 1) {
      return "no RGBA8/depth 24/stencil 8 desktop-GL pbuffer config";
    }
    // Desktop OpenGL, not GLES: MuJoCo 2.2 draws with the fixed-function pipeline.
    if (!api->BindAPI(EGL_OPENGL_API)) return "eglBindAPI(EGL_OPENGL_API) failed";
    EGLContext context = api->CreateContext(display, config, EGL_NO_CONTEXT, nullptr);
    if (context == EGL_NO_CONTEXT) {
      return "eglCreateContext failed (" + EglErrorName(api->GetError()) + ")";
    }
    EGLSurface surface = EGL_NO_SURFACE;
    if (!api->MakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
      // Without EGL_KHR_surfaceless_context: a small pbuffer to be current on.
      const EGLint pb[] = {EGL_WIDTH, kOsmesaBufferSize, EGL_HEIGHT, kOsmesaBufferSize, EGL_NONE};
      surface = api->CreatePbufferSurface(display, config, pb);
      if (surface == EGL_NO_SURFACE || !api->MakeCurrent(display, surface, surface, context)) {
        const std::string why = EglErrorName(api->GetError());
        if (surface != EGL_NO_SURFACE) api->DestroySurface(display, surface);
        api->DestroyContext(display, context);
        return "eglMakeCurrent failed (" + why + ")";
      }
    }
    display_ = display;
    context_ = context;
    surface_ = surface;
    description_ = "EGL " + std::to_string(major) + "." + std::to_string(minor) + ", " + label +
                   "; " +
                   GlStrings(reinterpret_cast<GetStringFn>(api->GetProcAddress("glGetString")));
    return "";
  }

 private:
  const EglApi* api_ = nullptr;
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  EGLSurface surface_ = EGL_NO_SURFACE;
};

Result<std::unique_ptr<GlContext>> CreateEgl() {
  auto api = LoadEgl();
  if (!api) return std::unexpected(api.error());
  const EglApi* a = *api;
  const char* client_ext = a->QueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  std::vector<std::string> tried;
  auto context = std::make_unique<EglContext>();

  // 1. Mesa's surfaceless platform (no X server, no GPU needed: llvmpipe).
  if (a->GetPlatformDisplayEXT && HasExtension(client_ext, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d =
        a->GetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    const std::string why = context->TryDisplay(a, d, "surfaceless platform");
    if (why.empty()) return context;
    tried.push_back("surfaceless platform: " + why);
  } else {
    tried.push_back("surfaceless platform: EGL_MESA_platform_surfaceless not offered");
  }
  // 2. The device platform (NVIDIA's driver offers this one).
  if (a->GetPlatformDisplayEXT && a->QueryDevicesEXT &&
      HasExtension(client_ext, "EGL_EXT_platform_device")) {
    EGLDeviceEXT devices[16];
    EGLint n = 0;
    if (a->QueryDevicesEXT(16, devices, &n) && n > 0) {
      for (EGLint i = 0; i < n; ++i) {
        EGLDisplay d = a->GetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        const std::string label = "device platform, device " + std::to_string(i);
        const std::string why = context->TryDisplay(a, d, label);
        if (why.empty()) return context;
        tried.push_back(label + ": " + why);
      }
    } else {
      tried.push_back("device platform: no devices");
    }
  } else {
    tried.push_back("device platform: EGL_EXT_platform_device not offered");
  }
  // 3. The default display (may need DISPLAY).
  {
    const std::string why =
        context->TryDisplay(a, a->GetDisplay(EGL_DEFAULT_DISPLAY), "default display");
    if (why.empty()) return context;
    tried.push_back("default display: " + why);
  }
  std::string message = "EGL: no offscreen context could be made; tried ";
  for (size_t i = 0; i < tried.size(); ++i) message += (i ? "; " : "") + tried[i];
  message += ". Try --backend osmesa";
  return Fail(ErrorCode::kInvalidInput, message);
}

// ---------------------------------------------------------------------------------------------
// OSMesa

struct OsmesaApi {
  void* lib = nullptr;
  OSMesaContext (*CreateContextExt)(GLenum, GLint, GLint, GLint, OSMesaContext) = nullptr;
  GLboolean (*MakeCurrent)(OSMesaContext, void*, GLenum, GLsizei, GLsizei) = nullptr;
  void (*DestroyContext)(OSMesaContext) = nullptr;
  OSMESAproc (*GetProcAddress)(const char*) = nullptr;
};

Result<const OsmesaApi*> LoadOsmesa() {
  static std::mutex mutex;
  static OsmesaApi api;
  std::lock_guard lock(mutex);
  if (api.lib) return &api;
  if (auto ok = CheckExclusive(GlBackend::kOsmesa); !ok) return std::unexpected(ok.error());
  auto lib = OpenLibrary(kOsmesaLibraries, "OSMesa");
  if (!lib) return std::unexpected(lib.error());
  OsmesaApi a;
  a.lib = *lib;
  Load(a.lib, a.CreateContextExt, "OSMesaCreateContextExt");
  Load(a.lib, a.MakeCurrent, "OSMesaMakeCurrent");
  Load(a.lib, a.DestroyContext, "OSMesaDestroyContext");
  Load(a.lib, a.GetProcAddress, "OSMesaGetProcAddress");
  if (!a.CreateContextExt || !a.MakeCurrent || !a.DestroyContext || !a.GetProcAddress) {
    return Fail(ErrorCode::kInvalidInput, "OSMesa: the library lacks OSMesaCreateContextExt");
  }
  api = a;
  return &api;
}

class OsmesaContext final : public GlContext {
 public:
  OsmesaContext(const OsmesaApi* api, OSMesaContext context)
      : GlContext(GlBackend::kOsmesa),
        api_(api),
        context_(context),
        buffer_(4 * kOsmesaBufferSize * kOsmesaBufferSize) {}
  ~OsmesaContext() override { api_->DestroyContext(context_); }

  Result<void> MakeCurrent() override {
    if (!api_->MakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, kOsmesaBufferSize,
                           kOsmesaBufferSize)) {
      return Fail(ErrorCode::kInternal, "OSMesa: OSMesaMakeCurrent failed");
    }
    return {};
  }

  void Describe() {
    description_ =
        "OSMesa; " + GlStrings(reinterpret_cast<GetStringFn>(api_->GetProcAddress("glGetString")));
  }

 private:
  const OsmesaApi* api_;
  OSMesaContext context_;
  std::vector<unsigned char> buffer_;
};

Result<std::unique_ptr<GlContext>> CreateOsmesa() {
  auto api = LoadOsmesa();
  if (!api) return std::unexpected(api.error());
  OSMesaContext c = (*api)->CreateContextExt(OSMESA_RGBA, 24, 8, 0, nullptr);
  if (!c) {
    return Fail(ErrorCode::kInvalidInput,
                "OSMesa: OSMesaCreateContextExt(RGBA, depth 24, stencil 8) failed");
  }
  auto context = std::make_unique<OsmesaContext>(*api, c);
  if (auto ok = context->MakeCurrent(); !ok) {
    return Fail(ErrorCode::kInvalidInput, ok.error().message);
  }
  context->Describe();
  return context;
}

}  // namespace

std::string_view ToString(GlBackend backend) {
  return backend == GlBackend::kEgl ? "egl" : "osmesa";
}

Result<GlBackend> ParseGlBackend(std::string_view name) {
  if (name == "egl") return GlBackend::kEgl;
  if (name == "osmesa") return GlBackend::kOsmesa;
  return Fail(ErrorCode::kInvalidInput,
              "unknown GL backend '" + std::string(name) + "': expected 'egl' or 'osmesa'");
}

Result<std::unique_ptr<GlContext>> GlContext::Create(GlBackend backend) {
  return backend == GlBackend::kEgl ? CreateEgl() : CreateOsmesa();
}

}  // namespace wrap::render
