// The assembly DAG as a node canvas drawn with ImDrawList: parts (left) and steps (columns to
// the right of their deepest input), edges input -> step, every node as wide as its name. Drag
// from a node's right port onto a step to make an input; drag a node's body to move it;
// right-click an edge to remove it; the wheel zooms, the middle button pans, "Fit" shows all.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include "gui/commands.h"
#include "gui/panels.h"

namespace wrap::gui {

namespace {

constexpr float kNodeH = 26.0f;   // node height (canvas units)
constexpr float kLabelH = 16.0f;  // room under a step for its "needs inputs" label
constexpr float kRowGap = 12.0f;  // between nodes of a column
constexpr float kColGap = 44.0f;  // between columns
constexpr float kPadX = 16.0f;    // text padding inside a node
constexpr float kMinZoom = 0.3f;

/// A node's width from its name at the default font size (canvas units).
float NodeWidth(const std::string& name) {
  const float text = ImGui::GetCurrentContext() ? ImGui::CalcTextSize(name.c_str()).x
                                                : 7.0f * static_cast<float>(name.size());
  return std::max(60.0f, text + 2.0f * kPadX);
}

/// The mating of a step in words, for its tooltip.
std::string MatingWords(const Step& s) {
  const Mating& m = s.mating;
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "step '%s': moves '%s' onto '%s'\n"
                "insertion axis (%.2f, %.2f, %.2f), force %.1f N, torque %.2f N m\n"
                "transverse fraction %.3f, offset %.4f m, approach %.3f m",
                s.name.c_str(), m.moved.empty() ? "?" : m.moved.c_str(),
                m.base.empty() ? "?" : m.base.c_str(), m.axis.x(), m.axis.y(), m.axis.z(),
                m.force_N, m.torque_Nm, m.transverse_fraction, m.offset_m, m.approach_m);
  return buf;
}

}  // namespace

std::string GraphPanel::Signature(const Project& project) {
  std::string sig;
  for (const Part& part : project.parts) sig += part.name + ";";
  for (const Step& step : project.steps) {
    sig += "|" + step.name + ":";
    for (const std::string& in : step.inputs) sig += in + ",";
  }
  return sig;
}

void GraphPanel::AutoLayout(const Project& project) {
  pos.clear();
  width.clear();
  signature = Signature(project);
  // Levels: a step one past its deepest input; a part one before the step that uses it (so a
  // chain of steps makes a staircase, not one long column of parts).
  std::map<std::string, int> level;
  std::function<int(const std::string&, int)> depth = [&](const std::string& n, int guard) {
    if (auto it = level.find(n); it != level.end()) return it->second;
    const Step* s = FindStep(project, n);
    int d = 0;
    if (s && guard < 64) {
      d = 1;
      for (const std::string& in : s->inputs) d = std::max(d, depth(in, guard + 1) + 1);
    }
    level[n] = d;
    return d;
  };
  std::map<std::string, int> consumer;  // node -> index of the step it is an input of
  for (size_t i = 0; i < project.steps.size(); ++i) {
    depth(project.steps[i].name, 0);
    for (const std::string& in : project.steps[i].inputs) consumer[in] = static_cast<int>(i);
  }
  for (const Part& part : project.parts) {
    auto c = consumer.find(part.name);
    level[part.name] =
        c == consumer.end() ? 0 : std::max(0, level[project.steps[c->second].name] - 1);
  }
  // Within a level, nodes in the order of the steps they feed (inputs of one step together).
  int deepest = 0;
  std::vector<std::vector<std::string>> by_level;
  auto add = [&](const std::string& n) {
    width[n] = NodeWidth(n);
    const int l = level[n];
    deepest = std::max(deepest, l);
    if (static_cast<int>(by_level.size()) <= l) by_level.resize(l + 1);
    by_level[l].push_back(n);
  };
  for (const Part& part : project.parts) add(part.name);
  for (const Step& step : project.steps) add(step.name);
  auto order = [&](const std::string& n) {
    auto c = consumer.find(n);
    return c == consumer.end() ? static_cast<int>(project.steps.size()) : c->second;
  };
  for (auto& names : by_level) {
    std::stable_sort(names.begin(), names.end(), [&](const std::string& a, const std::string& b) {
      return order(a) < order(b);
    });
  }
  // Two layouts: levels as columns (flow left to right) or as rows (top to bottom); the one that
  // shows the whole graph larger in the canvas is kept.
  auto zoom_of = [&](float w, float h) {
    return std::min((canvas_width - 24.0f) / std::max(1.0f, w),
                    (canvas_height - 24.0f) / std::max(1.0f, h));
  };
  std::map<std::string, ImVec2> across, down;
  float across_w = 0, across_h = 0, down_w = 0, down_h = 0;
  {
    float x = 0;
    for (const auto& names : by_level) {
      float col_w = 60.0f, y = 0;
      for (const std::string& n : names) {
        across[n] = ImVec2(x, y);
        y += kNodeH + kLabelH + kRowGap;
        col_w = std::max(col_w, width[n]);
      }
      across_h = std::max(across_h, y);
      x += col_w + kColGap;
    }
    across_w = x - kColGap;
  }
  {
    float y = 0;
    for (const auto& names : by_level) {
      float x = 0;
      for (const std::string& n : names) {
        down[n] = ImVec2(x, y);
        x += width[n] + kRowGap + 8.0f;
      }
      down_w = std::max(down_w, x);
      y += kNodeH + kLabelH + kColGap * 0.5f;
    }
    down_h = y;
  }
  vertical = zoom_of(down_w, down_h) > 1.15f * zoom_of(across_w, across_h);
  pos = vertical ? std::move(down) : std::move(across);
  fit_pending = true;
}

void GraphPanel::FitToView() {
  if (pos.empty()) return;
  float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
  for (const auto& [n, q] : pos) {
    const float w = width.count(n) ? width[n] : 120.0f;
    x0 = std::min(x0, q.x);
    y0 = std::min(y0, q.y);
    x1 = std::max(x1, q.x + w);
    y1 = std::max(y1, q.y + kNodeH + kLabelH);
  }
  const float margin = 12.0f;
  const float zx = (canvas_width - 2 * margin) / std::max(1.0f, x1 - x0);
  const float zy = (canvas_height - 2 * margin) / std::max(1.0f, y1 - y0);
  zoom = std::clamp(std::min(zx, zy), kMinZoom, 1.0f);
  // Centred horizontally when it fits, from the top.
  scroll.x =
      margin - x0 * zoom + std::max(0.0f, 0.5f * (canvas_width - 2 * margin - (x1 - x0) * zoom));
  scroll.y = margin - y0 * zoom;
  fit_pending = false;
}

namespace {

/// One frame's canvas: where it is on screen, the mouse, and the node geometry in screen
/// pixels from the panel's positions, zoom and scroll (read as they are when called).
struct Canvas {
  GraphPanel& g;
  ImDrawList* dl = nullptr;
  ImVec2 origin;         ///< Top-left corner on screen [px].
  bool hovered = false;  ///< The mouse is over the canvas.
  ImVec2 mouse;          ///< Mouse position on screen [px].
  float font = 0.0f;     ///< Text size at this zoom [px].
  float node_h = 0.0f;   ///< Node height at this zoom [px].

  float NodeW(const std::string& n) const {
    auto it = g.width.find(n);
    return (it == g.width.end() ? NodeWidth(n) : it->second) * g.zoom;
  }
  /// A node's top-left corner on screen (a node without a position gets one at the origin).
  ImVec2 Box(const std::string& n) const {
    const ImVec2 q = g.pos[n];
    return ImVec2(origin.x + g.scroll.x + q.x * g.zoom, origin.y + g.scroll.y + q.y * g.zoom);
  }
  bool Inside(const std::string& n, ImVec2 m) const {
    const ImVec2 b = Box(n);
    return m.x >= b.x && m.x <= b.x + NodeW(n) && m.y >= b.y && m.y <= b.y + node_h;
  }
  // Ports: out on the right and in on the left (levels as columns), or out at the bottom and
  // in at the top (levels as rows).
  ImVec2 Port(const std::string& n) const {
    const ImVec2 b = Box(n);
    return g.vertical ? ImVec2(b.x + 0.5f * NodeW(n), b.y + node_h)
                      : ImVec2(b.x + NodeW(n), b.y + node_h * 0.5f);
  }
  ImVec2 InPort(const std::string& n) const {
    const ImVec2 b = Box(n);
    return g.vertical ? ImVec2(b.x + 0.5f * NodeW(n), b.y) : ImVec2(b.x, b.y + node_h * 0.5f);
  }
  /// A link from `a` to `b`, bending along the flow.
  void Curve(ImVec2 a, ImVec2 b, ImU32 col) const {
    const float bend = 40.0f * g.zoom;
    if (g.vertical) {
      dl->AddBezierCubic(a, ImVec2(a.x, a.y + bend), ImVec2(b.x, b.y - bend), b, col, 2.0f);
    } else {
      dl->AddBezierCubic(a, ImVec2(a.x + bend, a.y), ImVec2(b.x - bend, b.y), b, col, 2.0f);
    }
  }
};

/// The edge under the mouse (its step and input), if any.
struct HoveredEdge {
  std::string step;
  std::string input;
};

/// Toolbar: new step, layout, fit; the selected step's delete and rename on their own line.
void DrawToolbar(GraphPanel& g, AppState& app, const Project& p) {
  ImGui::SetNextItemWidth(std::min(140.0f, ImGui::GetContentRegionAvail().x * 0.35f));
  ImGui::InputText("##newstep", &g.new_step_name);
  ImGui::SameLine();
  if (ImGui::Button("New step")) {
    const std::string name = UniqueName(p, g.new_step_name.empty() ? "step" : g.new_step_name);
    if (app.Do(AddStep(name))) app.selection.step = name;
  }
  ImGui::SameLine();
  if (ImGui::Button("Auto layout")) g.AutoLayout(p);
  ImGui::SameLine();
  if (ImGui::Button("Fit")) g.fit_pending = true;
  if (!FindStep(p, app.selection.step)) return;
  if (g.renaming != app.selection.step) {
    g.renaming = app.selection.step;
    g.rename_to = g.renaming;
  }
  if (ImGui::Button("Delete step")) {
    if (app.Do(RemoveStep(app.selection.step))) app.selection.step.clear();
  }
  ImGui::SameLine();
  ImGui::TextUnformatted("rename");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-1);
  if (ImGui::InputText("##rename", &g.rename_to, ImGuiInputTextFlags_EnterReturnsTrue)) {
    if (app.Do(RenameNode(app.selection.step, g.rename_to))) {
      g.pos[g.rename_to] = g.pos[app.selection.step];
      app.selection.step = g.rename_to;
      g.renaming = g.rename_to;
    }
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("New name of the step; Enter renames it");
}

/// The canvas fills the rest of the window: refits when its size changes, takes the mouse
/// (an invisible button), zooms about the mouse with the wheel, and draws its background and
/// grid inside a clip rectangle the caller pops.
Canvas BeginCanvas(GraphPanel& g) {
  Canvas c{g};
  c.dl = ImGui::GetWindowDrawList();
  c.origin = ImGui::GetCursorScreenPos();
  ImVec2 size = ImGui::GetContentRegionAvail();
  size.x = std::max(size.x, 50.0f);
  size.y = std::max(size.y, 50.0f);
  if (size.x != g.canvas_width || size.y != g.canvas_height) g.fit_pending = true;
  g.canvas_width = size.x;
  g.canvas_height = size.y;
  if (g.fit_pending) g.FitToView();
  ImGui::InvisibleButton("canvas", size,
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                             ImGuiButtonFlags_MouseButtonMiddle);
  c.hovered = ImGui::IsItemHovered();
  c.mouse = ImGui::GetIO().MousePos;
  const ImVec2 origin = c.origin;
  // Wheel: zoom about the mouse.
  if (c.hovered && ImGui::GetIO().MouseWheel != 0.0f) {
    const float z = std::clamp(g.zoom * std::pow(1.15f, ImGui::GetIO().MouseWheel), kMinZoom, 2.0f);
    const ImVec2 m(c.mouse.x - origin.x, c.mouse.y - origin.y);
    g.scroll.x = m.x - (m.x - g.scroll.x) * z / g.zoom;
    g.scroll.y = m.y - (m.y - g.scroll.y) * z / g.zoom;
    g.zoom = z;
  }
  ImDrawList* dl = c.dl;
  dl->PushClipRect(origin, ImVec2(origin.x + size.x, origin.y + size.y), true);
  dl->AddRectFilled(origin, ImVec2(origin.x + size.x, origin.y + size.y),
                    IM_COL32(30, 32, 36, 255));
  const float grid = 32.0f * g.zoom;
  for (float x = std::fmod(g.scroll.x, grid); x < size.x; x += grid) {
    dl->AddLine(ImVec2(origin.x + x, origin.y), ImVec2(origin.x + x, origin.y + size.y),
                IM_COL32(45, 48, 54, 255));
  }
  for (float y = std::fmod(g.scroll.y, grid); y < size.y; y += grid) {
    dl->AddLine(ImVec2(origin.x, origin.y + y), ImVec2(origin.x + size.x, origin.y + y),
                IM_COL32(45, 48, 54, 255));
  }
  c.font = ImGui::GetFontSize() * g.zoom;
  c.node_h = kNodeH * g.zoom;
  return c;
}

/// Edges input -> step (the moved input's orange); the one under the mouse red.
HoveredEdge DrawEdges(const Canvas& c, const Project& p) {
  HoveredEdge hovered_edge;
  for (const Step& step : p.steps) {
    for (const std::string& in : step.inputs) {
      if (!c.g.pos.count(in)) continue;
      const ImVec2 a = c.Port(in), b = c.InPort(step.name);
      const bool moved = step.mating.moved == in;
      ImU32 col = moved ? IM_COL32(240, 160, 60, 255) : IM_COL32(150, 170, 200, 255);
      const ImVec2 mid((a.x + b.x) * 0.5f, (a.y + b.y) * 0.5f);
      if (c.hovered && std::abs(c.mouse.x - mid.x) < 10 && std::abs(c.mouse.y - mid.y) < 10) {
        hovered_edge.step = step.name;
        hovered_edge.input = in;
        col = IM_COL32(255, 90, 80, 255);
      }
      c.Curve(a, b, col);
      c.dl->AddCircleFilled(mid, 3.0f, col);
    }
  }
  return hovered_edge;
}

/// One node: box (a part with its colour's stripe), border by state, full name, ports, and
/// under the failed step its label. True when the mouse is over it.
bool DrawNode(const Canvas& c, const AppState& app, const std::string& n, bool is_step,
              const Rgba* color) {
  ImDrawList* dl = c.dl;
  const float zoom = c.g.zoom;
  const float node_h = c.node_h;
  const ImVec2 b = c.Box(n);
  const float w = c.NodeW(n);
  const bool selected = is_step ? app.selection.step == n : app.selection.part == n;
  const bool failed = is_step && n == c.g.marked;
  const ImU32 fill = failed    ? IM_COL32(110, 40, 40, 255)
                     : is_step ? IM_COL32(60, 70, 95, 255)
                               : IM_COL32(55, 58, 62, 255);
  dl->AddRectFilled(b, ImVec2(b.x + w, b.y + node_h), fill, 4.0f);
  if (color) {
    dl->AddRectFilled(
        b, ImVec2(b.x + 6 * zoom, b.y + node_h),
        IM_COL32(static_cast<int>(255 * (*color)[0]), static_cast<int>(255 * (*color)[1]),
                 static_cast<int>(255 * (*color)[2]), 255),
        4.0f);
  }
  const ImU32 border = failed     ? IM_COL32(255, 80, 70, 255)
                       : selected ? IM_COL32(255, 220, 90, 255)
                                  : IM_COL32(110, 115, 125, 255);
  dl->AddRect(b, ImVec2(b.x + w, b.y + node_h), border, 4.0f, 0,
              failed     ? 3.0f
              : selected ? 2.5f
                         : 1.0f);
  dl->AddText(nullptr, c.font, ImVec2(b.x + kPadX * zoom, b.y + 0.5f * (node_h - c.font)),
              IM_COL32(230, 230, 230, 255), n.c_str());
  dl->AddCircleFilled(c.Port(n), 4.5f * std::max(zoom, 0.6f), IM_COL32(200, 200, 90, 255));
  if (is_step) {
    dl->AddCircleFilled(c.InPort(n), 3.5f * std::max(zoom, 0.6f), IM_COL32(150, 170, 200, 255));
  }
  if (failed) {
    dl->AddText(nullptr, c.font * 0.9f, ImVec2(b.x, b.y + node_h + 1), IM_COL32(255, 110, 100, 255),
                "the last run failed here");
  }
  return c.Inside(n, c.mouse);
}

/// Nodes: full names; the step where the last run failed marked red; a step short of inputs
/// says so. Returns the node under the mouse ("" none).
std::string DrawNodes(const Canvas& c, AppState& app, const Project& p) {
  GraphPanel& g = c.g;
  g.marked = app.run_failure ? app.run_failure->StepName() : std::string();
  if (!FindStep(p, g.marked)) g.marked.clear();
  app.canvas_marked = g.marked;
  std::string node_under_mouse;
  for (const Part& part : p.parts) {
    if (DrawNode(c, app, part.name, false, &part.color)) node_under_mouse = part.name;
  }
  for (const Step& step : p.steps) {
    if (DrawNode(c, app, step.name, true, nullptr)) node_under_mouse = step.name;
    if (step.inputs.size() < 2 && step.name != g.marked) {
      const ImVec2 b = c.Box(step.name);
      c.dl->AddText(nullptr, c.font * 0.9f, ImVec2(b.x, b.y + c.node_h + 1),
                    IM_COL32(240, 120, 100, 255),
                    step.inputs.empty() ? "needs 2 inputs" : "needs 1 more input");
    }
  }
  return node_under_mouse;
}

/// Mouse: press on a port starts a link, on a body selects and moves; release on a step makes
/// the input; right-click on an edge removes it; the middle button pans.
void HandleMouse(const Canvas& c, AppState& app, const Project& p,
                 const std::string& node_under_mouse, const HoveredEdge& hovered_edge) {
  GraphPanel& g = c.g;
  if (c.hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    g.drag_from.clear();
    g.moving.clear();
    for (const auto& [n, q] : g.pos) {
      const ImVec2 pp = c.Port(n);
      if (std::hypot(c.mouse.x - pp.x, c.mouse.y - pp.y) < 8.0f && NameTaken(p, n)) {
        g.drag_from = n;
      }
    }
    if (g.drag_from.empty() && !node_under_mouse.empty()) {
      g.moving = node_under_mouse;
      if (FindStep(p, g.moving)) {
        app.selection.step = g.moving;
      } else {
        app.selection.part = g.moving;
      }
    }
  }
  if (!g.drag_from.empty() && g.pos.count(g.drag_from)) {
    c.Curve(c.Port(g.drag_from), c.mouse, IM_COL32(255, 230, 120, 255));
  }
  if (!g.moving.empty() && ImGui::IsMouseDragging(ImGuiMouseButton_Left) && g.pos.count(g.moving)) {
    g.pos[g.moving].x += ImGui::GetIO().MouseDelta.x / g.zoom;
    g.pos[g.moving].y += ImGui::GetIO().MouseDelta.y / g.zoom;
  }
  if (ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
    if (!g.drag_from.empty() && !node_under_mouse.empty() && node_under_mouse != g.drag_from) {
      if (FindStep(p, node_under_mouse)) {
        if (app.Do(AddInput(node_under_mouse, g.drag_from))) {
          app.selection.step = node_under_mouse;
        }
      } else {
        app.Notify("Refused: '" + node_under_mouse +
                   "' is a part: drop a link on a step to make an input");
      }
    }
    g.drag_from.clear();
    g.moving.clear();
  }
  if (c.hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Right) && !hovered_edge.step.empty()) {
    app.Do(RemoveInput(hovered_edge.step, hovered_edge.input));
  }
  if (c.hovered && ImGui::IsMouseDragging(ImGuiMouseButton_Middle)) {
    g.scroll.x += ImGui::GetIO().MouseDelta.x;
    g.scroll.y += ImGui::GetIO().MouseDelta.y;
  }
}

/// Tooltips: a step's mating in words, a part's hint, or the hovered edge.
void ShowTooltips(const Canvas& c, const Project& p, const std::string& node_under_mouse,
                  const HoveredEdge& hovered_edge) {
  if (c.hovered && hovered_edge.step.empty() && !node_under_mouse.empty() &&
      c.g.drag_from.empty()) {
    if (const Step* s = FindStep(p, node_under_mouse)) {
      std::string tip = MatingWords(*s);
      if (node_under_mouse == c.g.marked) {
        tip += "\n\nThe last run failed here (see Problems).";
      }
      ImGui::SetTooltip("%s", tip.c_str());
    } else {
      ImGui::SetTooltip(
          "part '%s' (drag its port, the yellow dot, onto a step to make it an "
          "input)",
          node_under_mouse.c_str());
    }
  }
  if (!hovered_edge.step.empty()) {
    ImGui::SetTooltip("'%s' -> '%s' (right-click: remove)", hovered_edge.input.c_str(),
                      hovered_edge.step.c_str());
  }
}

}  // namespace

void GraphPanel::Draw(AppState& app, const PanelRect& r) {
  PlaceNextWindow(r);
  if (!ImGui::Begin("Assembly graph", nullptr, ImGuiWindowFlags_NoCollapse)) {
    ImGui::End();
    return;
  }
  const Project& p = app.doc.project();
  bool unplaced = false;
  for (const Part& part : p.parts) unplaced |= !pos.count(part.name);
  for (const Step& step : p.steps) unplaced |= !pos.count(step.name);
  if (unplaced || Signature(p) != signature) AutoLayout(p);

  DrawToolbar(*this, app, p);
  const Canvas canvas = BeginCanvas(*this);
  const HoveredEdge hovered_edge = DrawEdges(canvas, p);
  const std::string node_under_mouse = DrawNodes(canvas, app, p);
  HandleMouse(canvas, app, p, node_under_mouse, hovered_edge);
  canvas.dl->PopClipRect();
  ShowTooltips(canvas, p, node_under_mouse, hovered_edge);
  ImGui::End();
}

}  // namespace wrap::gui
