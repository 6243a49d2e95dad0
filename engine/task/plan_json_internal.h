// The plan file's insides, shared by plan_json_write.cpp (SerializePlan), plan_json_read.cpp
// (ParsePlan), plan_json_fields.cpp (typed field readers) and plan_json_match.cpp
// (CheckPlanMatchesProject): the format's name and version, JSON paths for messages, and the
// field readers. Not part of the plan module's API (nlohmann/json stays out of plan_json.h).
//
// Reading: the first problem found is thrown as a BadField and turned into the Error at the
// boundary (ParsePlan), so every reader can simply return the value it read.
#pragma once

#include <climits>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/pose.h"

namespace wrap::plan_json_internal {

using json = nlohmann::json;
using ojson = nlohmann::ordered_json;

inline constexpr std::string_view kFormatName = "wrap-plan";
inline constexpr int kFormatVersion = 1;

// A JSON path for messages: Join("actions[3]", "keyframe") = "actions[3].keyframe",
// Index("actions", 3) = "actions[3]".
std::string Join(const std::string& path, std::string_view key);
std::string Index(const std::string& path, size_t i);

struct BadField {
  std::string path;     // JSON path, e.g. "actions[3].keyframe.q.ur5e_a"; empty: the document.
  std::string message;  // What is wrong.
};

[[noreturn]] void Bad(const std::string& path, std::string message);

// "an object", "a string", ... for "expected X, found Y".
std::string TypeName(const json& j);
const json& ExpectObject(const json& j, const std::string& path);
const json& ExpectArray(const json& j, const std::string& path);
// Refuses keys of `obj` outside `known` (a typo would otherwise go unnoticed).
void CheckKeys(const json& obj, const std::string& path,
               std::initializer_list<std::string_view> known);
// The member `key` of `obj`, or nullptr.
const json* Find(const json& obj, std::string_view key);
// The member `key` of `obj` at `path`; a BadField when it is missing.
const json& Member(const json& obj, const std::string& path, std::string_view key);

// Typed values: `...Value(j, path)` reads `j` itself, the others the member `key` of `obj`.
double NumberValue(const json& j, const std::string& path);  // finite
double Number(const json& obj, const std::string& path, std::string_view key);
double NonNegative(const json& obj, const std::string& path, std::string_view key);
long long IntegerValue(const json& j, const std::string& path, long long lo, long long hi);
int Int(const json& obj, const std::string& path, std::string_view key, int lo = INT_MIN,
        int hi = INT_MAX);
long long Count(const json& obj, const std::string& path, std::string_view key);  // >= 0
bool Bool(const json& obj, const std::string& path, std::string_view key);
std::string StringValue(const json& j, const std::string& path);
std::string String(const json& obj, const std::string& path, std::string_view key);
// A list of unique, non-empty names.
std::vector<std::string> Names(const json& obj, const std::string& path, std::string_view key,
                               bool allow_empty_list);
Vec3 Vector3(const json& obj, const std::string& path, std::string_view key);
// {"xyz": [...], "rpy": [...]} as an isometry.
Iso3 PoseValue(const json& obj, const std::string& path, std::string_view key);

}  // namespace wrap::plan_json_internal
