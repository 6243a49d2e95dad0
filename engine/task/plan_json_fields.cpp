// The plan file's typed field readers (plan_json_internal.h): each reads one value at a JSON path
// and throws a BadField naming that path when the value is missing or of the wrong kind.
#include <cmath>
#include <set>
#include <utility>

#include "task/plan_json_internal.h"

namespace wrap::plan_json_internal {

[[noreturn]] void Bad(const std::string& path, std::string message) {
  throw BadField{path, std::move(message)};
}

std::string Join(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string Index(const std::string& path, size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

std::string TypeName(const json& j) {
  switch (j.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return "a boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      return "an integer";
    case json::value_t::number_float:
      return "a number";
    default:
      return "an unsupported value";
  }
}

const json& ExpectObject(const json& j, const std::string& path) {
  if (!j.is_object()) Bad(path, "expected an object, found " + TypeName(j));
  return j;
}

const json& ExpectArray(const json& j, const std::string& path) {
  if (!j.is_array()) Bad(path, "expected an array, found " + TypeName(j));
  return j;
}

// Refuses keys of `obj` outside `known` (a typo would otherwise go unnoticed).
void CheckKeys(const json& obj, const std::string& path,
               std::initializer_list<std::string_view> known) {
  for (const auto& [key, value] : obj.items()) {
    bool found = false;
    for (std::string_view k : known) found = found || key == k;
    if (!found) {
      std::string list;
      for (std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
      Bad(Join(path, key), "unknown field (known here: " + list + ")");
    }
  }
}

const json* Find(const json& obj, std::string_view key) {
  auto it = obj.find(key);
  return it == obj.end() ? nullptr : &*it;
}

const json& Member(const json& obj, const std::string& path, std::string_view key) {
  const json* j = Find(obj, key);
  if (!j) Bad(Join(path, key), "required field is missing");
  return *j;
}

double NumberValue(const json& j, const std::string& path) {
  if (!j.is_number()) Bad(path, "expected a number, found " + TypeName(j));
  const double v = j.get<double>();
  if (!std::isfinite(v)) Bad(path, "expected a finite number");
  return v;
}

double Number(const json& obj, const std::string& path, std::string_view key) {
  return NumberValue(Member(obj, path, key), Join(path, key));
}

double NonNegative(const json& obj, const std::string& path, std::string_view key) {
  const double v = Number(obj, path, key);
  if (v < 0.0) Bad(Join(path, key), "expected a number >= 0, found " + std::to_string(v));
  return v;
}

long long IntegerValue(const json& j, const std::string& path, long long lo, long long hi) {
  if (!j.is_number_integer()) {
    Bad(path,
        "expected an integer, found " + (j.is_number() ? std::string("a fraction") : TypeName(j)));
  }
  const auto out_of_range = [&](const std::string& found) {
    Bad(path, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                  "], found " + found);
  };
  if (j.is_number_unsigned()) {
    const auto u = j.get<unsigned long long>();
    if (u > static_cast<unsigned long long>(hi) ||
        (lo > 0 && u < static_cast<unsigned long long>(lo))) {
      out_of_range(std::to_string(u));
    }
    return static_cast<long long>(u);
  }
  const long long v = j.get<long long>();
  if (v < lo || v > hi) out_of_range(std::to_string(v));
  return v;
}

int Int(const json& obj, const std::string& path, std::string_view key, int lo, int hi) {
  return static_cast<int>(IntegerValue(Member(obj, path, key), Join(path, key), lo, hi));
}

long long Count(const json& obj, const std::string& path, std::string_view key) {
  return IntegerValue(Member(obj, path, key), Join(path, key), 0, LLONG_MAX);
}

bool Bool(const json& obj, const std::string& path, std::string_view key) {
  const json& j = Member(obj, path, key);
  if (!j.is_boolean()) Bad(Join(path, key), "expected true or false, found " + TypeName(j));
  return j.get<bool>();
}

std::string StringValue(const json& j, const std::string& path) {
  if (!j.is_string()) Bad(path, "expected a string, found " + TypeName(j));
  return j.get<std::string>();
}

std::string String(const json& obj, const std::string& path, std::string_view key) {
  return StringValue(Member(obj, path, key), Join(path, key));
}

// A list of unique, non-empty names.
std::vector<std::string> Names(const json& obj, const std::string& path, std::string_view key,
                               bool allow_empty_list) {
  const std::string at = Join(path, key);
  const json& list = ExpectArray(Member(obj, path, key), at);
  if (list.empty() && !allow_empty_list) Bad(at, "expected at least one name");
  std::vector<std::string> names;
  std::set<std::string> seen;
  for (size_t i = 0; i < list.size(); ++i) {
    std::string name = StringValue(list[i], Index(at, i));
    if (name.empty()) Bad(Index(at, i), "empty name");
    if (!seen.insert(name).second) Bad(Index(at, i), "duplicate name '" + name + "'");
    names.push_back(std::move(name));
  }
  return names;
}

Vec3 Vector3(const json& obj, const std::string& path, std::string_view key) {
  const std::string at = Join(path, key);
  const json& j = Member(obj, path, key);
  if (!j.is_array() || j.size() != 3) {
    Bad(at, "expected an array of 3 numbers, found " +
                (j.is_array() ? "an array of " + std::to_string(j.size()) : TypeName(j)));
  }
  Vec3 v;
  for (size_t i = 0; i < 3; ++i) v[static_cast<Eigen::Index>(i)] = NumberValue(j[i], Index(at, i));
  return v;
}

Iso3 PoseValue(const json& obj, const std::string& path, std::string_view key) {
  const std::string at = Join(path, key);
  const json& j = ExpectObject(Member(obj, path, key), at);
  CheckKeys(j, at, {"xyz", "rpy"});
  Pose pose;
  pose.xyz = Vector3(j, at, "xyz");
  pose.rpy = Vector3(j, at, "rpy");
  return ToIsometry(pose);
}

}  // namespace wrap::plan_json_internal
