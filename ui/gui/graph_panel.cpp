// The assembly DAG as a node canvas drawn with ImDrawList: parts (left) and steps (columns to
// the right of their deepest input), edges input -> step. Drag from a node's right port onto a
// step to make an input; drag a node's body to move it; right-click an edge to remove it.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <functional>

#include "gui/commands.h"
#include "gui/panels.h"

namespace wrap::gui {

namespace {

constexpr float kNodeH = 26.0f, kRowH = 40.0f;
float kNodeW = 130.0f;  // shrinks with the columns when the DAG is deep (AutoLayout)

const Step* FindStep(const Project& p, const std::string& name) {
  for (const Step& s : p.steps) {
    if (s.name == name) return &s;
  }
  return nullptr;
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
  signature = Signature(project);
  std::map<std::string, int> column;
  std::function<int(const std::string&, int)> depth = [&](const std::string& n, int guard) {
    if (auto it = column.find(n); it != column.end()) return it->second;
    const Step* s = FindStep(project, n);
    int d = 0;
    if (s && guard < 64) {
      d = 1;
      for (const std::string& in : s->inputs) d = std::max(d, depth(in, guard + 1) + 1);
    }
    column[n] = d;
    return d;
  };
  int deepest = 0;
  for (const Step& step : project.steps) deepest = std::max(deepest, depth(step.name, 0));
  // Columns fit the canvas width; nodes narrow with them.
  const float col_w =
      std::clamp((canvas_width - 150.0f) / static_cast<float>(std::max(1, deepest)), 70.0f, 170.0f);
  kNodeW = std::min(130.0f, col_w - 14.0f);
  const float kColW = col_w;
  std::map<int, int> rows;
  // Steps first in DAG order, so that inputs sit near their step; parts in file order.
  for (const Part& part : project.parts) {
    const int c = depth(part.name, 0);
    pos[part.name] = ImVec2(c * kColW, rows[c]++ * kRowH);
  }
  for (const Step& step : project.steps) {
    const int c = depth(step.name, 0);
    // Centre a step between its inputs when there is room.
    float y = rows[c] * kRowH;
    if (!step.inputs.empty()) {
      float mean = 0;
      for (const std::string& in : step.inputs) mean += pos.count(in) ? pos[in].y : y;
      mean /= static_cast<float>(step.inputs.size());
      y = std::max(y, mean);
    }
    pos[step.name] = ImVec2(c * kColW, y);
    rows[c] = static_cast<int>(y / kRowH) + 1;
  }
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
  canvas_width = std::max(200.0f, ImGui::GetContentRegionAvail().x);
  if (unplaced || Signature(p) != signature) AutoLayout(p);

  ImGui::SetNextItemWidth(110);
  ImGui::InputText("##newstep", &new_step_name);
  ImGui::SameLine();
  if (ImGui::Button("New step")) {
    const std::string name = UniqueName(p, new_step_name.empty() ? "step" : new_step_name);
    if (app.Do(AddStep(name))) app.selection.step = name;
  }
  ImGui::SameLine();
  if (ImGui::Button("Auto layout")) AutoLayout(p);
  if (FindStep(p, app.selection.step)) {
    ImGui::SameLine();
    if (ImGui::Button("Delete step")) {
      if (app.Do(RemoveStep(app.selection.step))) app.selection.step.clear();
    }
    ImGui::SameLine();
    ImGui::SetNextItemWidth(110);
    if (ImGui::InputText("rename", &rename_to, ImGuiInputTextFlags_EnterReturnsTrue)) {
      if (app.Do(RenameNode(app.selection.step, rename_to))) {
        pos[rename_to] = pos[app.selection.step];
        app.selection.step = rename_to;
      }
    }
  }

  // The canvas.
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImVec2 size = ImGui::GetContentRegionAvail();
  size.x = std::max(size.x, 50.0f);
  size.y = std::max(size.y, 50.0f);
  ImGui::InvisibleButton("canvas", size,
                         ImGuiButtonFlags_MouseButtonLeft | ImGuiButtonFlags_MouseButtonRight |
                             ImGuiButtonFlags_MouseButtonMiddle);
  const bool hovered = ImGui::IsItemHovered();
  const ImVec2 mouse = ImGui::GetIO().MousePos;
  dl->PushClipRect(origin, ImVec2(origin.x + size.x, origin.y + size.y), true);
  dl->AddRectFilled(origin, ImVec2(origin.x + size.x, origin.y + size.y),
                    IM_COL32(30, 32, 36, 255));
  for (float x = std::fmod(scroll.x, 32.0f); x < size.x; x += 32.0f) {
    dl->AddLine(ImVec2(origin.x + x, origin.y), ImVec2(origin.x + x, origin.y + size.y),
                IM_COL32(45, 48, 54, 255));
  }
  for (float y = std::fmod(scroll.y, 32.0f); y < size.y; y += 32.0f) {
    dl->AddLine(ImVec2(origin.x, origin.y + y), ImVec2(origin.x + size.x, origin.y + y),
                IM_COL32(45, 48, 54, 255));
  }
  auto box = [&](const std::string& n) {
    const ImVec2 q = pos[n];
    return ImVec2(origin.x + scroll.x + q.x, origin.y + scroll.y + q.y);
  };
  auto inside = [&](const std::string& n, ImVec2 m) {
    const ImVec2 b = box(n);
    return m.x >= b.x && m.x <= b.x + kNodeW && m.y >= b.y && m.y <= b.y + kNodeH;
  };
  auto port = [&](const std::string& n) {
    const ImVec2 b = box(n);
    return ImVec2(b.x + kNodeW, b.y + kNodeH * 0.5f);
  };
  auto in_port = [&](const std::string& n) {
    const ImVec2 b = box(n);
    return ImVec2(b.x, b.y + kNodeH * 0.5f);
  };

  // Edges, with right-click to remove.
  std::string hovered_edge_step, hovered_edge_input;
  for (const Step& step : p.steps) {
    for (const std::string& in : step.inputs) {
      if (!pos.count(in)) continue;
      const ImVec2 a = port(in), b = in_port(step.name);
      const bool moved = step.mating.moved == in;
      ImU32 col = moved ? IM_COL32(240, 160, 60, 255) : IM_COL32(150, 170, 200, 255);
      // Hover test on the segment's bounding band.
      const ImVec2 mid((a.x + b.x) * 0.5f, (a.y + b.y) * 0.5f);
      if (hovered && std::abs(mouse.x - mid.x) < 10 && std::abs(mouse.y - mid.y) < 10) {
        hovered_edge_step = step.name;
        hovered_edge_input = in;
        col = IM_COL32(255, 90, 80, 255);
      }
      dl->AddBezierCubic(a, ImVec2(a.x + 50, a.y), ImVec2(b.x - 50, b.y), b, col, 2.0f);
      dl->AddCircleFilled(mid, 3.0f, col);
    }
  }

  // Nodes.
  std::string node_under_mouse;
  auto draw_node = [&](const std::string& n, bool is_step, const Rgba* color) {
    const ImVec2 b = box(n);
    const bool selected = is_step ? app.selection.step == n : app.selection.part == n;
    const ImU32 fill = is_step ? IM_COL32(60, 70, 95, 255) : IM_COL32(55, 58, 62, 255);
    dl->AddRectFilled(b, ImVec2(b.x + kNodeW, b.y + kNodeH), fill, 4.0f);
    if (color) {
      dl->AddRectFilled(
          b, ImVec2(b.x + 6, b.y + kNodeH),
          IM_COL32(static_cast<int>(255 * (*color)[0]), static_cast<int>(255 * (*color)[1]),
                   static_cast<int>(255 * (*color)[2]), 255),
          4.0f);
    }
    dl->AddRect(b, ImVec2(b.x + kNodeW, b.y + kNodeH),
                selected ? IM_COL32(255, 220, 90, 255) : IM_COL32(110, 115, 125, 255), 4.0f, 0,
                selected ? 2.5f : 1.0f);
    const ImVec4 clip(b.x, b.y, b.x + kNodeW - 6, b.y + kNodeH);
    dl->AddText(nullptr, 0.0f, ImVec2(b.x + 10, b.y + 5), IM_COL32(230, 230, 230, 255), n.c_str(),
                nullptr, 0.0f, &clip);
    dl->AddCircleFilled(port(n), 4.5f, IM_COL32(200, 200, 90, 255));
    if (is_step) dl->AddCircleFilled(in_port(n), 3.5f, IM_COL32(150, 170, 200, 255));
    if (inside(n, mouse)) node_under_mouse = n;
  };
  for (const Part& part : p.parts) draw_node(part.name, false, &part.color);
  for (const Step& step : p.steps) {
    draw_node(step.name, true, nullptr);
    if (step.inputs.size() < 2) {
      const ImVec2 b = box(step.name);
      dl->AddText(ImVec2(b.x, b.y + kNodeH + 1), IM_COL32(240, 120, 100, 255),
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
        rename_to = moving;
      } else {
        app.selection.part = moving;
      }
    }
  }
  if (!drag_from.empty() && pos.count(drag_from)) {
    const ImVec2 a = port(drag_from);
    dl->AddBezierCubic(a, ImVec2(a.x + 50, a.y), ImVec2(mouse.x - 50, mouse.y), mouse,
                       IM_COL32(255, 230, 120, 255), 2.0f);
  }
  if (!moving.empty() && ImGui::IsMouseDragging(ImGuiMouseButton_Left) && pos.count(moving)) {
    pos[moving].x += ImGui::GetIO().MouseDelta.x;
    pos[moving].y += ImGui::GetIO().MouseDelta.y;
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
    ImGui::SetTooltip("%s (drag its right port onto a step to make it an input)",
                      node_under_mouse.c_str());
  }
  if (!hovered_edge_step.empty()) {
    ImGui::SetTooltip("'%s' -> '%s' (right-click: remove)", hovered_edge_input.c_str(),
                      hovered_edge_step.c_str());
  }
  ImGui::End();
}

}  // namespace wrap::gui
