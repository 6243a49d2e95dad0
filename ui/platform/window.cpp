#include "platform/window.h"

#include <GLFW/glfw3.h>
#if defined(__SANITIZE_ADDRESS__)
#include <dlfcn.h>
#include <link.h>
#endif
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <utility>
#include <vector>

namespace wrap::platform {

namespace {

// GL entry points used here, looked up through GLFW: the executable links no GL library (one
// GL platform library per process, ui/render/gl_context.h).
using PfnViewport = void (*)(int, int, int, int);
using PfnClearColor = void (*)(float, float, float, float);
using PfnClear = void (*)(unsigned int);
using PfnReadBuffer = void (*)(unsigned int);
using PfnPixelStorei = void (*)(unsigned int, int);
using PfnReadPixels = void (*)(int, int, int, int, unsigned int, unsigned int, void*);
using PfnFinish = void (*)();
struct GlFunctions {
  PfnViewport viewport = nullptr;
  PfnClearColor clear_color = nullptr;
  PfnClear clear = nullptr;
  PfnReadBuffer read_buffer = nullptr;
  PfnPixelStorei pixel_storei = nullptr;
  PfnReadPixels read_pixels = nullptr;
  PfnFinish finish = nullptr;
};
GlFunctions gl;

constexpr unsigned int kColorBufferBit = 0x4000;
constexpr unsigned int kDepthBufferBit = 0x0100;
constexpr unsigned int kBack = 0x0405;
constexpr unsigned int kPackAlignment = 0x0D05;
constexpr unsigned int kRgb = 0x1907;
constexpr unsigned int kUnsignedByte = 0x1401;

std::string glfw_error;  // last GLFW error, for Create's message
std::vector<std::string>* dropped_sink = nullptr;

void OnGlfwError(int code, const char* description) {
  glfw_error = "GLFW error " + std::to_string(code) + ": " + (description ? description : "");
}

// Keys pressed and released between two frames (a quick tap while a software-GL frame takes
// 100-250 ms, or xdotool's key) would never be seen down by Dear ImGui 1.86, which keeps only the
// state of each key: Ctrl+Z was lost. A release that would reach ImGui in the same frame as its
// press is passed on at the start of the frame after.
struct KeyEvent {
  GLFWwindow* window;
  int key, scancode, action, mods;
  int deliver_at;  // frame number
};
int frame_number = 0;  // counts BeginFrame calls
bool polling = false;  // inside BeginFrame's poll (events reach this frame, else the next)
std::vector<std::pair<int, int>> key_seen;  // key -> frame its last press reaches ImGui
std::vector<KeyEvent> deferred_releases;

void OnKey(GLFWwindow* window, int key, int scancode, int action, int mods) {
  const int seen = polling ? frame_number : frame_number + 1;
  auto pressed = std::find_if(key_seen.begin(), key_seen.end(),
                              [&](const std::pair<int, int>& k) { return k.first == key; });
  if (action == GLFW_PRESS) {
    if (pressed == key_seen.end()) {
      key_seen.push_back({key, seen});
    } else {
      pressed->second = seen;
    }
  } else if (action == GLFW_RELEASE && pressed != key_seen.end() && pressed->second >= seen) {
    deferred_releases.push_back({window, key, scancode, action, mods, pressed->second + 1});
    return;
  }
  ImGui_ImplGlfw_KeyCallback(window, key, scancode, action, mods);
}

void OnDrop(GLFWwindow*, int count, const char** paths) {
  if (!dropped_sink) return;
  for (int i = 0; i < count; ++i) dropped_sink->push_back(paths[i]);
}

std::vector<std::string> dropped;

#if defined(__SANITIZE_ADDRESS__)
// Mesa's DRI driver (loaded by the GL context, dlclosed at exit) keeps strings of its option
// tables (about 5 kB) that LeakSanitizer reports at exit; once unloaded, its frames have no module
// name, so no suppression can match them. Sanitizer builds keep the driver mapped to the end
// (RTLD_NODELETE on the already loaded object), and tests/sanitizers/lsan.supp names it.
int PinDriDriver(dl_phdr_info* info, size_t, void*) {
  const char* name = info->dlpi_name;
  if (name && (std::strstr(name, "_dri.so") || std::strstr(name, "libgallium"))) {
    dlopen(name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
  }
  return 0;
}
void PinGlDriversForLeakReports() { dl_iterate_phdr(PinDriDriver, nullptr); }
#else
void PinGlDriversForLeakReports() {}
#endif

}  // namespace

Result<std::unique_ptr<Window>> Window::Create(const WindowOptions& options) {
  glfwSetErrorCallback(OnGlfwError);
  if (!glfwInit()) {
    const char* display = std::getenv("DISPLAY");
    return Fail(ErrorCode::kInvalidInput,
                "cannot open a window: " + glfw_error +
                    (display ? "" : " (DISPLAY is not set: run under X, or xvfb-run)"));
  }
  std::unique_ptr<Window> w(new Window());
  // Single-sampled: ImGui antialiases its own shapes, and the viewport's cell is drawn in
  // MuJoCo's offscreen buffer, multisampled only when drawing fine (render/window_renderer.h).
  // A multisampled window would cost every frame under software GL and could not take the blit.
  glfwWindowHint(GLFW_SAMPLES, 0);
  w->window_ =
      glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
  if (!w->window_) {
    return Fail(ErrorCode::kInvalidInput, "cannot create a window with OpenGL: " + glfw_error);
  }
  glfwMakeContextCurrent(w->window_);
  PinGlDriversForLeakReports();
  glfwSwapInterval(options.vsync ? 1 : 0);
  gl.viewport = reinterpret_cast<PfnViewport>(glfwGetProcAddress("glViewport"));
  gl.clear_color = reinterpret_cast<PfnClearColor>(glfwGetProcAddress("glClearColor"));
  gl.clear = reinterpret_cast<PfnClear>(glfwGetProcAddress("glClear"));
  gl.read_buffer = reinterpret_cast<PfnReadBuffer>(glfwGetProcAddress("glReadBuffer"));
  gl.pixel_storei = reinterpret_cast<PfnPixelStorei>(glfwGetProcAddress("glPixelStorei"));
  gl.read_pixels = reinterpret_cast<PfnReadPixels>(glfwGetProcAddress("glReadPixels"));
  gl.finish = reinterpret_cast<PfnFinish>(glfwGetProcAddress("glFinish"));
  if (!gl.viewport || !gl.clear_color || !gl.clear || !gl.read_buffer || !gl.pixel_storei ||
      !gl.read_pixels || !gl.finish) {
    return Fail(ErrorCode::kInvalidInput, "the OpenGL context lacks basic functions");
  }
  dropped_sink = &dropped;
  glfwSetDropCallback(w->window_, OnDrop);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  w->imgui_made_ = true;
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // the layout is the app's, the same on every start
  io.ConfigFlags |= ImGuiConfigFlags_NavEnableKeyboard;
  ImGui::StyleColorsDark();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 0.0f;
  style.FrameRounding = 2.0f;
  w->glfw_backend_ = ImGui_ImplGlfw_InitForOpenGL(w->window_, true);
  glfwSetKeyCallback(w->window_, OnKey);  // forwards to the backend's, see OnKey
  w->gl3_backend_ = w->glfw_backend_ && ImGui_ImplOpenGL3_Init("#version 130");
  if (!w->gl3_backend_) {
    return Fail(ErrorCode::kInvalidInput, "Dear ImGui's OpenGL 3 backend did not start");
  }
  return w;
}

Window::~Window() {
  if (gl3_backend_) ImGui_ImplOpenGL3_Shutdown();
  if (glfw_backend_) ImGui_ImplGlfw_Shutdown();
  if (imgui_made_) ImGui::DestroyContext();
  if (window_) glfwDestroyWindow(window_);
  dropped_sink = nullptr;
  glfwTerminate();
}

void Window::BeginFrame() {
  ++frame_number;
  std::vector<KeyEvent> later;
  for (const KeyEvent& e : std::exchange(deferred_releases, {})) {
    if (e.deliver_at > frame_number) {
      later.push_back(e);
    } else {
      ImGui_ImplGlfw_KeyCallback(e.window, e.key, e.scancode, e.action, e.mods);
    }
  }
  deferred_releases = std::move(later);
  polling = true;
  glfwPollEvents();
  polling = false;
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
}

void Window::EndFrame(const std::function<void()>& draw_scene, render::Image* capture) {
  ImGui::Render();
  const int w = width(), h = height();
  gl.viewport(0, 0, w, h);
  gl.clear_color(0.11f, 0.12f, 0.13f, 1.0f);
  gl.clear(kColorBufferBit | kDepthBufferBit);
  if (draw_scene) draw_scene();
  gl.viewport(0, 0, w, h);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  if (capture) {
    gl.finish();
    gl.read_buffer(kBack);
    gl.pixel_storei(kPackAlignment, 1);
    std::vector<std::uint8_t> rows(static_cast<size_t>(w) * h * 3);
    gl.read_pixels(0, 0, w, h, kRgb, kUnsignedByte, rows.data());
    capture->width = w;
    capture->height = h;
    capture->rgb.resize(rows.size());
    const size_t stride = static_cast<size_t>(w) * 3;
    for (int y = 0; y < h; ++y) {  // GL rows start at the bottom
      std::copy_n(rows.data() + (h - 1 - y) * stride, stride, capture->rgb.data() + y * stride);
    }
  }
  glfwSwapBuffers(window_);
}

void Window::WaitEvents(double timeout_s) { glfwWaitEventsTimeout(std::max(0.0, timeout_s)); }

bool Window::close_requested() const { return glfwWindowShouldClose(window_) != 0; }

void Window::set_close_requested(bool value) {
  glfwSetWindowShouldClose(window_, value ? GLFW_TRUE : GLFW_FALSE);
}

void Window::SetTitle(const std::string& title) { glfwSetWindowTitle(window_, title.c_str()); }

int Window::width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return w;
}

int Window::height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return h;
}

std::vector<std::string> Window::TakeDroppedFiles() { return std::exchange(dropped, {}); }

double Window::time() const { return glfwGetTime(); }

}  // namespace wrap::platform
