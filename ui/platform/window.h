// The platform glue: a GLFW window with an OpenGL context and Dear ImGui's GLFW and OpenGL 3
// backends. The only place that includes GLFW or the ImGui backends; the panels see ImGui only.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/result.h"
#include "render/image.h"

struct GLFWwindow;

namespace wrap::platform {

/// Options of Window::Create.
struct WindowOptions {
  int width = 1600;            ///< Window width [px].
  int height = 960;            ///< Window height [px].
  std::string title = "Wrap";  ///< Title bar text.
  bool vsync = true;           ///< Swap on vertical sync (off for scripted runs).
};

/// A GLFW window whose OpenGL context (compatibility profile, as MuJoCo 2.2's renderer needs) is
/// current on the thread that made it, with an ImGui context bound to it. One per process.
class Window {
 public:
  /// Opens the window. Fails with kInvalidInput when there is no display (DISPLAY unset, X
  /// server unreachable) or no GL context can be made; the message says which.
  static Result<std::unique_ptr<Window>> Create(const WindowOptions& options);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  /// Handles window events and starts an ImGui frame.
  void BeginFrame();
  /// Ends the ImGui frame: clears the window, calls `draw_scene` (GL drawing under the panels,
  /// e.g. MuJoCo's viewport), draws the panels, and shows the frame. When `capture` is given,
  /// the whole window is read into it before the frame is shown.
  void EndFrame(const std::function<void()>& draw_scene, render::Image* capture = nullptr);

  /// True when the user asked to close the window (title bar, Alt+F4).
  bool close_requested() const;
  /// Sets or clears the close request (cleared when the app asks to confirm first).
  void set_close_requested(bool value);
  /// Sets the title bar text.
  void SetTitle(const std::string& title);
  /// Framebuffer size [px].
  int width() const;
  int height() const;
  /// Files dropped onto the window since the last call.
  std::vector<std::string> TakeDroppedFiles();
  /// Seconds since the window opened.
  double time() const;
  /// Sleeps until an input event arrives (mouse, keys, resize, a dropped file) or `timeout_s`
  /// passes: the interactive loop's pause while nothing on screen changes.
  void WaitEvents(double timeout_s);

 private:
  Window() = default;
  GLFWwindow* window_ = nullptr;
  bool imgui_made_ = false;
  bool glfw_backend_ = false;
  bool gl3_backend_ = false;
};

}  // namespace wrap::platform
