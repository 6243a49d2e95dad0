#include "model/entity_path.h"

#include <cstdlib>
#include <vector>

namespace wrap {

namespace {

// Splits "key[12].rest" into ("key", 12, "rest"); index -1 when there is no "[N]".
struct Head {
  std::string key;
  long index = -1;
  std::string rest;
};

Head Split(const std::string& path) {
  Head h;
  size_t i = 0;
  while (i < path.size() && path[i] != '.' && path[i] != '[') ++i;
  h.key = path.substr(0, i);
  if (i < path.size() && path[i] == '[') {
    const size_t close = path.find(']', i);
    if (close != std::string::npos) {
      char* end = nullptr;
      const std::string digits = path.substr(i + 1, close - i - 1);
      const long v = std::strtol(digits.c_str(), &end, 10);
      if (!digits.empty() && end && *end == '\0') h.index = v;
      i = close + 1;
    }
  }
  if (i < path.size() && path[i] == '.') ++i;
  h.rest = i < path.size() ? path.substr(i) : std::string();
  return h;
}

template <typename T>
const std::string* NameAt(const std::vector<T>& list, long index) {
  if (index < 0 || index >= static_cast<long>(list.size())) return nullptr;
  return &list[static_cast<size_t>(index)].name;
}

}  // namespace

std::string EntityRef::Label() const {
  switch (kind) {
    case EntityKind::kProject:
      return "project";
    case EntityKind::kPart:
      return "part '" + name + "'";
    case EntityKind::kStep:
      return "step '" + name + "'";
    case EntityKind::kRobot:
      return "robot '" + name + "'";
    case EntityKind::kMobileBase:
      return "mobile base '" + name + "'";
    case EntityKind::kTable:
      return "table";
    case EntityKind::kPlanner:
      return "planner defaults";
    case EntityKind::kOther:
      return "project";
  }
  return "project";
}

EntityRef EntityOfPath(const Project& project, const std::string& json_path) {
  EntityRef ref;
  if (json_path.empty()) return ref;
  const Head h = Split(json_path);
  const std::string* name = nullptr;
  if (h.key == "parts") {
    ref.kind = EntityKind::kPart;
    name = NameAt(project.parts, h.index);
  } else if (h.key == "steps") {
    ref.kind = EntityKind::kStep;
    name = NameAt(project.steps, h.index);
  } else if (h.key == "robots") {
    ref.kind = EntityKind::kRobot;
    name = NameAt(project.robots, h.index);
  } else if (h.key == "mobile_bases") {
    ref.kind = EntityKind::kMobileBase;
    name = NameAt(project.mobile_bases, h.index);
  } else if (h.key == "table" && h.index < 0) {
    ref.kind = EntityKind::kTable;
    ref.field = h.rest;
    return ref;
  } else if (h.key == "planner" && h.index < 0) {
    ref.kind = EntityKind::kPlanner;
    ref.field = h.rest;
    return ref;
  } else if (h.index < 0) {
    ref.kind = EntityKind::kProject;
    ref.field = json_path;
    return ref;
  }
  if (!name) {
    ref.kind = EntityKind::kOther;
    ref.field = json_path;
    return ref;
  }
  ref.name = *name;
  ref.field = h.rest;
  return ref;
}

std::string FormatNamed(const Diagnostic& d, const Project& project) {
  const EntityRef ref = EntityOfPath(project, d.path);
  const bool named = (ref.kind == EntityKind::kPart || ref.kind == EntityKind::kStep ||
                      ref.kind == EntityKind::kRobot || ref.kind == EntityKind::kMobileBase) &&
                     !ref.name.empty();
  if (!named) return Format(d);
  Diagnostic shown = d;
  const std::string label = ref.Label();
  shown.path = label + (ref.field.empty() ? std::string() : ", " + ref.field);
  // A message that starts by naming its entity need not say it twice.
  if (shown.message.starts_with(label + ": ")) shown.message.erase(0, label.size() + 2);
  return Format(shown);
}

std::string FormatNamed(const Diagnostic& d, const Project* project) {
  return project ? FormatNamed(d, *project) : Format(d);
}

}  // namespace wrap
