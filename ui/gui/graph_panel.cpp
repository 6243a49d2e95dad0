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

const Step* FindStep(const Project& p, const std::string& name) {
  for (const Step& s : p.steps) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

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

  // Toolbar: new step, layout, fit; the selected step's delete and rename on their own line.
  ImGui::SetNextItemWidth(std::min(140.0f, ImGui::GetContentRegionAvail().x * 0.35f));
  ImGui::InputText("##newstep", &new_step_name);
  ImGui::SameLine();
  if (ImGui::Button("New step")) {
    const std::string name = UniqueName(p, new_step_name.empty() ? "step" : new_step_name);
    if (app.Do(AddStep(name))) app.selection.step = name;
  }
  ImGui::SameLine();
  if (ImGui::Button("Auto layout")) AutoLayout(p);
  ImGui::SameLine();
  if (ImGui::Button("Fit")) fit_pending = true;
  if (FindStep(p, app.selection.step)) {
    if (renaming != app.selection.step) {
      renaming = app.selection.step;
      rename_to = renaming;
    }
    if (ImGui::Button("Delete step")) {
      if (app.Do(RemoveStep(app.selection.step))) app.selection.step.clear();
    }
    ImGui::SameLine();
    ImGui::TextUnformatted("rename");
    ImGui::SameLine();
    ImGui::SetNextItemWidth(-1);
    if (ImGui::InputText("##rename", &rename_to, ImGuiInputTextFlags_EnterReturnsTrue)) {
      if (app.Do(RenameNode(app.selection.step, rename_to))) {
        pos[rename_to] = pos[app.selection.step];
        app.selection.step = rename_to;
        renaming = rename_to;
      }
    }
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("New name of the step; Enter renames it");
  }

  // The canvas.
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImVec2 size = ImGui::GetContentRegionAvail();
  size.x = std::max(size.x, 50.0f);
  size.y = std::max(size.y, 50.0f);
  if (size.x != canvas_width || size.y != canvas_height) fit_pending = true;
  canvas_width = size.x;
  canvas_height = size.y;
  if (fit_pending) FitToView();
  ImGui::InvisibleButton("canvas", size,
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                             ImGuiButtonFlags_MouseButtonMiddle);
  const bool hovered = ImGui::IsItemHovered();
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  // Wheel: zoom about the mouse.
  if (hovered && ImGui::GetIO().MouseWheel != 0.0f) {
    const float z = std::clamp(zoom * std::pow(1.15f, ImGui::GetIO().MouseWheel), kMinZoom, 2.0f);
    const ImVec2 m(mouse.x - origin.x, mouse.y - origin.y);
    scroll.x = m.x - (m.x - scroll.x) * z / zoom;
    scroll.y = m.y - (m.y - scroll.y) * z / zoom;
    zoom = z;
  }
  dl->PushClipRect(origin, ImVec2(origin.x + size.x, origin.y + size.y), true);
  dl->AddRectFilled(origin, ImVec2(origin.x + size.x, origin.y + size.y),
                    IM_COL32(30, 32, 36, 255));
  const float grid = 32.0f * zoom;
  for (float x = std::fmod(scroll.x, grid); x < size.x; x += grid) {
    dl->AddLine(ImVec2(origin.x + x, origin.y), ImVec2(origin.x + x, origin.y + size.y),
                IM_COL32(45, 48, 54, 255));
  }
  for (float y = std::fmod(scroll.y, grid); y < size.y; y += grid) {
    dl->AddLine(ImVec2(origin.x, origin.y + y), ImVec2(origin.x + size.x, origin.y + y),
                IM_COL32(45, 48, 54, 255));
  }
  const float font = ImGui::GetFontSize() * zoom;
  auto node_w = [&](const std::string& n) {
    auto it = width.find(n);
    return (it == width.end() ? NodeWidth(n) : it->second) * zoom;
  };
  const float node_h = kNodeH * zoom;
  auto box = [&](const std::string& n) {
    const ImVec2 q = pos[n];
    return ImVec2(origin.x + scroll.x + q.x * zoom, origin.y + scroll.y + q.y * zoom);
  };
  auto inside = [&](const std::string& n, ImVec2 m) {
    const ImVec2 b = box(n);
    return m.x >= b.x && m.x <= b.x + node_w(n) && m.y >= b.y && m.y <= b.y + node_h;
  };
  // Ports: out on the right and in on the left (levels as columns), or out at the bottom and
  // in at the top (levels as rows).
  auto port = [&](const std::string& n) {
    const ImVec2 b = box(n);
    return vertical ? ImVec2(b.x + 0.5f * node_w(n), b.y + node_h)
                    : ImVec2(b.x + node_w(n), b.y + node_h * 0.5f);
  };
  auto in_port = [&](const std::string& n) {
    const ImVec2 b = box(n);
    return vertical ? ImVec2(b.x + 0.5f * node_w(n), b.y) : ImVec2(b.x, b.y + node_h * 0.5f);
  };
  auto curve = [&](ImVec2 a, ImVec2 b, ImU32 col) {
    const float bend = 40.0f * zoom;
    if (vertical) {
      dl->AddBezierCubic(a, ImVec2(a.x, a.y + bend), ImVec2(b.x, b.y - bend), b, col, 2.0f);
    } else {
      dl->AddBezierCubic(a, ImVec2(a.x + bend, a.y), ImVec2(b.x - bend, b.y), b, col, 2.0f);
    }
  };

  // Edges, with right-click to remove.
  std::string hovered_edge_step, hovered_edge_input;
  for (const Step& step : p.steps) {
    for (const std::string& in : step.inputs) {
      if (!pos.count(in)) continue;
      const ImVec2 a = port(in), b = in_port(step.name);
      const bool moved = step.mating.moved == in;
      ImU32 col = moved ? IM_COL32(240, 160, 60, 255) : IM_COL32(150, 170, 200, 255);
      const ImVec2 mid((a.x + b.x) * 0.5f, (a.y + b.y) * 0.5f);
      if (hovered && std::abs(mouse.x - mid.x) < 10 && std::abs(mouse.y - mid.y) < 10) {
        hovered_edge_step = step.name;
        hovered_edge_input = in;
        col = IM_COL32(255, 90, 80, 255);
      }
      curve(a, b, col);
      dl->AddCircleFilled(mid, 3.0f, col);
    }
  }

  // Nodes: full names; the step where the last run failed marked red.
  marked = app.run_failure ? app.run_failure->StepName() : std::string();
  if (!FindStep(p, marked)) marked.clear();
  app.canvas_marked = marked;
  std::string node_under_mouse;
  auto draw_node = [&](const std::string& n, bool is_step, const Rgba* color) {
    const ImVec2 b = box(n);
    const float w = node_w(n);
    const bool selected = is_step ? app.selection.step == n : app.selection.part == n;
    const bool failed = is_step && n == marked;
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
    dl->AddText(nullptr, font, ImVec2(b.x + kPadX * zoom, b.y + 0.5f * (node_h - font)),
                IM_COL32(230, 230, 230, 255), n.c_str());
    dl->AddCircleFilled(port(n), 4.5f * std::max(zoom, 0.6f), IM_COL32(200, 200, 90, 255));
    if (is_step) {
      dl->AddCircleFilled(in_port(n), 3.5f * std::max(zoom, 0.6f), IM_COL32(150, 170, 200, 255));
    }
    if (failed) {
      dl->AddText(nullptr, font * 0.9f, ImVec2(b.x, b.y + node_h + 1), IM_COL32(255, 110, 100, 255),
                  "the last run failed here");
    }
    if (inside(n, mouse)) node_under_mouse = n;
  };
  for (const Part& part : p.parts) draw_node(part.name, false, &part.color);
  for (const Step& step : p.steps) {
    draw_node(step.name, true, nullptr);
    if (step.inputs.size() < 2 && step.name != marked) {
      const ImVec2 b = box(step.name);
      dl->AddText(nullptr, font * 0.9f, ImVec2(b.x, b.y + node_h + 1), IM_COL32(240, 120, 100, 255),
                  step.inputs.empty() ? "needs 2 inputs" : "needs 1 more input");
    }
  }

  // Mouse: press on a port starts a link, on a body selects and moves; release on a step
  // makes the input.
  if (hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    drag_from.clear();
    moving.clear();
    for (const auto& [n, q] : pos) {
      const ImVec2 pp = port(n);
      if (std::hypot(mouse.x - pp.x, mouse.y - pp.y) < 8.0f && NameTaken(p, n)) drag_from = n;
    }
    if (drag_from.empty() && !node_under_mouse.empty()) {
      moving = node_under_mouse;
      if (FindStep(p, moving)) {
        app.selection.step = moving;
      } else {
        app.selection.part = moving;
      }
    }
  }
  if (!drag_from.empty() && pos.count(drag_from)) {
    curve(port(drag_from), mouse, IM_COL32(255, 230, 120, 255));
  }
  if (!moving.empty() && ImGui::IsMouseDragging(ImGuiMouseButton_Left) && pos.count(moving)) {
    pos[moving].x += ImGui::GetIO().MouseDelta.x / zoom;
    pos[moving].y += ImGui::GetIO().MouseDelta.y / zoom;
  }
  if (ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
    if (!drag_from.empty() && !node_under_mouse.empty() && node_under_mouse != drag_from) {
      if (FindStep(p, node_under_mouse)) {
        if (app.Do(AddInput(node_under_mouse, drag_from))) app.selection.step = node_under_mouse;
      } else {
        app.Notify("Refused: '" + node_under_mouse +
                   "' is a part: drop a link on a step to make an input");
      }
    }
    drag_from.clear();
    moving.clear();
  }
  if (hovered && ImGui::IsMouseClicked(ImGuiMouseButton_Right) && !hovered_edge_step.empty()) {
    app.Do(RemoveInput(hovered_edge_step, hovered_edge_input));
  }
  if (hovered && ImGui::IsMouseDragging(ImGuiMouseButton_Middle)) {
    scroll.x += ImGui::GetIO().MouseDelta.x;
    scroll.y += ImGui::GetIO().MouseDelta.y;
  }
  dl->PopClipRect();
  if (hovered && hovered_edge_step.empty() && !node_under_mouse.empty() && drag_from.empty()) {
    if (const Step* s = FindStep(p, node_under_mouse)) {
      std::string tip = MatingWords(*s);
      if (node_under_mouse == marked) {
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
  if (!hovered_edge_step.empty()) {
    ImGui::SetTooltip("'%s' -> '%s' (right-click: remove)", hovered_edge_input.c_str(),
                      hovered_edge_step.c_str());
  }
  ImGui::End();
}

}  // namespace wrap::gui
