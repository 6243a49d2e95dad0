// Bad inputs to every CLI command (DESIGN.md's contract): each malformed project, mesh, URDF or
// plan file gives exit 2 and a message on stderr that names the file, the field and the problem,
// and no output file (or temporary file) is left behind.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "reliability_fixture.h"

namespace wrap::reliability {
namespace {

using cli::CliRun;
using cli::Wrap;
using nlohmann::json;

/// One malformed input: how it breaks the blocks project (its JSON, or a file beside it) and the
/// phrases stderr must hold (the file's name among them).
struct BadProject {
  std::string name;                                  ///< Also the project file's stem.
  std::function<void(json&, const fs::path&)> edit;  ///< Breaks the project or its files.
  std::vector<std::string> phrases;                  ///< Each must appear on stderr.
  std::string raw;  ///< When set: the project file's text instead of the (edited) JSON.
};

std::string Binary(const std::vector<uint8_t>& bytes) { return {bytes.begin(), bytes.end()}; }

/// A 3-joint URDF with `joint` (one or more <joint> elements over links a, b, c) for the arm.
std::string Urdf(const std::string& body) {
  return R"(<robot name="bad"><link name="a"/><link name="b"/><link name="c"/>)" + body +
         "</robot>";
}
const std::string kLimit = R"(<limit lower="-1" upper="1" velocity="1" effort="1"/>)";
std::string Joint(const std::string& name, const std::string& type, const std::string& parent,
                  const std::string& child, const std::string& extra = "") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\">" +
         (type == "revolute" ? kLimit : "") + extra + "<parent link=\"" + parent +
         "\"/><child link=\"" + child + "\"/></joint>";
}

/// Sets part `i`'s mesh to `file` with `bytes` written beside the project.
std::function<void(json&, const fs::path&)> Mesh(int i, const std::string& file,
                                                 const std::string& bytes) {
  return [=](json& p, const fs::path& dir) {
    WriteBytes(dir / file, bytes);
    p["parts"][i]["mesh"] = file;
  };
}

/// Sets robot r2's URDF to `file` with `text` written beside the project.
std::function<void(json&, const fs::path&)> RobotUrdf(const std::string& file,
                                                      const std::string& text) {
  return [=](json& p, const fs::path& dir) {
    WriteBytes(dir / file, text);
    p["robots"][1]["urdf"] = file;
  };
}

std::vector<BadProject> BadProjects() {
  const std::string good = BlocksProject().dump(2);
  std::string half_binary_stl(80, 'x');
  half_binary_stl += Binary({0xe8, 0x03, 0, 0});  // 1000 triangles announced, none follow
  half_binary_stl += std::string(100, '\0');
  const std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
      "property float z\nelement face 10\nproperty list uchar int vertex_indices\nend_header\n";
  return {
      // Project files.
      {"empty", nullptr, {"empty.json", "malformed JSON", "line 1"}, " "},
      {"not_json", nullptr, {"not_json.json", "malformed JSON"}, "{ not json"},
      {"truncated",
       nullptr,
       {"truncated.json", "malformed JSON", "unexpected end"},
       good.substr(0, good.size() / 2)},
      {"top_level_array",
       nullptr,
       {"top_level_array.json", "JSON object at the top level"},
       "[1, 2]"},
      {"binary_bytes",
       nullptr,
       {"binary_bytes.json", "malformed JSON"},
       Binary({0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 0x0d})},
      {"number_overflow",
       nullptr,
       {"number_overflow.json", "malformed JSON", "1e999"},
       std::string(good).replace(good.find("0.2"), 3, "1e999")},
      {"wrong_format",
       [](json& p, const fs::path&) { p["format"] = "wrap-plan"; },
       {"wrong_format.json", "format", "wrap-project"}},
      {"newer_version",
       [](json& p, const fs::path&) { p["version"] = 2; },
       {"newer_version.json", "version", "unsupported version 2"}},
      {"parts_not_array",
       [](json& p, const fs::path&) { p["parts"] = "base"; },
       {"parts_not_array.json", "parts: error: expected an array"}},
      {"mesh_missing_key",
       [](json& p, const fs::path&) { p["parts"][0].erase("mesh"); },
       {"mesh_missing_key.json", "parts[0].mesh", "required field is missing"}},
      {"negative_mass",
       [](json& p, const fs::path&) { p["parts"][0]["mass_kg"] = -1; },
       {"negative_mass.json", "parts[0].mass_kg", "must be positive"}},
      {"zero_scale",
       [](json& p, const fs::path&) { p["parts"][1]["scale"] = 0; },
       {"zero_scale.json", "parts[1].scale", "must be positive"}},
      {"wrong_type",
       [](json& p, const fs::path&) {
         p["table"] = {{"friction", "high"}};
       },
       {"wrong_type.json", "table.friction", "expected a number, found a string"}},
      {"short_vector",
       [](json& p, const fs::path&) {
         p["parts"][0]["initial_pose"]["xyz"] = {0, 0};
       },
       {"short_vector.json", "parts[0].initial_pose.xyz", "3 numbers"}},
      {"duplicate_name",
       [](json& p, const fs::path&) { p["parts"][1]["name"] = "base"; },
       {"duplicate_name.json", "parts[1].name", "already used"}},
      {"three_inputs",
       [](json& p, const fs::path&) {
         p["steps"][0]["inputs"] = {"base", "peg", "base"};
       },
       {"three_inputs.json", "steps[0].inputs", "exactly two inputs"}},
      {"unknown_input",
       [](json& p, const fs::path&) {
         p["steps"][0]["inputs"] = {"base", "pin"};
       },
       {"unknown_input.json", "steps[0].inputs[1]", "unknown input 'pin'"}},
      {"cycle",
       [](json& p, const fs::path&) {
         p["steps"] = json::parse(R"([
           {"name": "s1", "inputs": ["base", "s2"], "mating": {"moved": "base", "base": "s2"}},
           {"name": "s2", "inputs": ["peg", "s1"], "mating": {"moved": "peg", "base": "s1"}}])");
       },
       {"cycle.json", "steps", "cycle"}},
      {"moved_not_input",
       [](json& p, const fs::path&) { p["steps"][0]["mating"]["moved"] = "r1"; },
       {"moved_not_input.json", "steps[0].mating.moved", "not an input"}},
      {"zero_axis",
       [](json& p, const fs::path&) {
         p["steps"][0]["mating"]["axis"] = {0, 0, 0};
       },
       {"zero_axis.json", "steps[0].mating.axis", "must not be zero"}},
      {"unknown_model",
       [](json& p, const fs::path&) { p["robots"][0]["model"] = "ur3"; },
       {"unknown_model.json", "robots[0].model", "unknown robot model 'ur3'"}},
      {"unknown_end_effector",
       [](json& p, const fs::path&) { p["robots"][0]["end_effector"] = "magnet"; },
       {"unknown_end_effector.json", "robots[0].end_effector", "unknown end effector"}},
      {"undefined_variable",
       [](json& p, const fs::path&) { p["parts"][0]["mesh"] = "${NOPE}/base.stl"; },
       {"undefined_variable.json", "parts[0].mesh", "${NOPE}", "not defined"}},
      // Meshes.
      {"mesh_not_found",
       [](json& p, const fs::path&) { p["parts"][0]["mesh"] = "nope.stl"; },
       {"mesh_not_found.json", "parts[0].mesh", "'nope.stl' not found"}},
      {"mesh_is_directory",
       [](json& p, const fs::path&) { p["parts"][0]["mesh"] = "."; },
       {"mesh_is_directory.json", "parts[0].mesh", "is a directory"}},
      {"mesh_empty", Mesh(0, "empty.stl", ""), {"parts[0].mesh", "empty.stl", "is empty"}},
      {"stl_text", Mesh(0, "text.stl", "hello, not a mesh\n"), {"parts[0].mesh", "text.stl"}},
      {"stl_no_facets",
       Mesh(0, "nofacets.stl", "solid x\n facet garbage\n"),
       {"parts[0].mesh", "nofacets.stl", "no triangles"}},
      {"stl_binary_truncated",
       Mesh(0, "truncated.stl", half_binary_stl),
       {"parts[0].mesh", "truncated.stl"}},
      {"obj_index_out_of_range",
       Mesh(1, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n"),
       {"parts[1].mesh", "range.obj", "out of range"}},
      {"obj_points_only",
       Mesh(1, "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
       {"parts[1].mesh", "points.obj", "no triangles"}},
      {"obj_nan_vertex",
       Mesh(1, "nan.obj",
            "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\n"),
       {"parts[1].mesh", "nan.obj", "non-finite"}},
      {"obj_degenerate",
       Mesh(1, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 3 2\n"),
       {"parts[1].mesh", "flat.obj", "degenerate"}},
      {"ply_truncated",
       Mesh(0, "truncated.ply", ply_header + "0 0 0\n1 0 0\n"),
       {"parts[0].mesh", "truncated.ply", "truncated"}},
      {"ply_binary_bad_index",
       Mesh(0, "badindex.ply",
            "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
            "property float y\nproperty float z\nelement face 1\n"
            "property list uchar int vertex_indices\nend_header\n" +
                std::string(36, '\0') + Binary({3, 0, 0, 0, 0, 1, 0, 0, 0, 0x70, 0x11, 1, 0})),
       {"parts[0].mesh", "badindex.ply", "out of range"}},
      // URDF files.
      {"urdf_missing",
       [](json& p, const fs::path&) { p["robots"][1]["urdf"] = "gone.urdf"; },
       {"urdf_missing.json", "robots[1].urdf", "gone.urdf"}},
      {"urdf_empty", RobotUrdf("empty.urdf", ""), {"robots[1].urdf", "empty.urdf"}},
      {"urdf_malformed_xml",
       RobotUrdf("broken.urdf", "<robot name='x'><link name='a'>"),
       {"robots[1].urdf", "broken.urdf"}},
      {"urdf_no_joint",
       RobotUrdf("nojoint.urdf", "<robot name='x'><link name='a'/></robot>"),
       {"robots[1].urdf", "nojoint.urdf", "no revolute"}},
      {"urdf_floating",
       RobotUrdf("floating.urdf", Urdf(Joint("j", "floating", "a", "b"))),
       {"robots[1].urdf", "floating.urdf", "floating"}},
      {"urdf_closed_loop",
       RobotUrdf("loop.urdf",
                 Urdf(Joint("j1", "revolute", "a", "b") + Joint("j2", "revolute", "b", "c") +
                      Joint("j3", "revolute", "c", "b"))),
       {"robots[1].urdf", "loop.urdf", "closed loop"}},
      {"urdf_limits_reversed",
       RobotUrdf("limits.urdf",
                 R"(<robot name="x"><link name="a"/><link name="b"/><joint name="j" )"
                 R"(type="revolute"><limit lower="1" upper="-1" velocity="1" effort="1"/>)"
                 R"(<parent link="a"/><child link="b"/></joint></robot>)"),
       {"robots[1].urdf", "limits.urdf", "above upper"}},
      {"urdf_joint_to_itself",
       RobotUrdf("itself.urdf",
                 Urdf(Joint("j1", "revolute", "a", "b") + Joint("j2", "revolute", "c", "c"))),
       {"robots[1].urdf", "itself.urdf", "joint 'j2' connects link 'c' to itself"}},
      {"urdf_two_tips",
       RobotUrdf("tips.urdf",
                 Urdf(Joint("j1", "revolute", "a", "b") + Joint("j2", "revolute", "a", "c"))),
       {"robots[1].urdf", "tips.urdf", "tip"}},
      {"urdf_unknown_link",
       RobotUrdf("unknown.urdf", Urdf(Joint("j", "revolute", "a", "zz"))),
       {"robots[1].urdf", "unknown.urdf", "zz"}},
      {"urdf_zero_axis",
       RobotUrdf("axis.urdf", Urdf(Joint("j", "revolute", "a", "b", R"(<axis xyz="0 0 0"/>)"))),
       {"robots[1].urdf", "axis.urdf", "axis"}},
      {"urdf_mesh_missing",
       RobotUrdf("meshless.urdf",
                 R"(<robot name="x"><link name="a"/><link name="b"><collision><geometry>)"
                 R"(<mesh filename="gone.stl"/></geometry></collision></link>)" +
                     Joint("j", "revolute", "a", "b") + "</robot>"),
       {"robots[1].urdf", "meshless.urdf", "gone.stl"}},
  };
}

/// Nothing but an empty render folder may be in `out` after a refused command.
void ExpectNoOutput(const fs::path& out, const std::string& what) {
  for (const std::string& f : ListFiles(out)) {
    EXPECT_EQ(f, "render") << what << " left '" << f << "' in the output folder";
  }
}

/// How stderr names the field at a JSON path of `project`: "parts[1].mesh" of a project whose
/// second part is 'peg' reads "part 'peg', mesh" (entities by name, not by list index).
std::string Named(const std::string& phrase, const json& project) {
  static const std::regex path(R"(^(parts|steps|robots|mobile_bases)\[(\d+)\](\.(.*))?$)");
  static const std::map<std::string, std::string> kind = {
      {"parts", "part"}, {"steps", "step"}, {"robots", "robot"}, {"mobile_bases", "mobile base"}};
  std::smatch m;
  if (!std::regex_match(phrase, m, path)) return phrase;
  const json* list = project.is_object() && project.contains(m[1].str()) ? &project[m[1].str()]
                                                                          : nullptr;
  const size_t i = std::stoul(m[2].str());
  if (!list || !list->is_array() || i >= list->size() || !(*list)[i].contains("name") ||
      !(*list)[i]["name"].is_string() || (*list)[i]["name"].get<std::string>().empty()) {
    return phrase;
  }
  const std::string name = kind.at(m[1].str()) + " '" + (*list)[i]["name"].get<std::string>() + "'";
  return m[4].matched ? name + ", " + m[4].str() : name;
}

void ExpectBadInput(const CliRun& r, const std::vector<std::string>& phrases,
                    const std::string& what) {
  EXPECT_EQ(r.code, 2) << what << "\n" << r.err;
  for (const std::string& phrase : phrases) {
    EXPECT_NE(r.err.find(phrase), std::string::npos)
        << what << ": '" << phrase << "' not on stderr:\n"
        << r.err;
  }
}

// The blocks project itself is valid, so each case below fails for its one defect.
TEST(MalformedInputs, BlocksProjectIsValid) {
  TempDir dir("good");
  WriteBlocksFiles(dir.path);
  const fs::path project = WriteBytes(dir.path / "blocks.json", BlocksProject().dump(2));
  const CliRun r = Wrap({"validate", project.string()});
  EXPECT_EQ(r.code, 0) << r.err;
}

// Every malformed project, mesh or URDF through every command that reads a project.
TEST(MalformedInputs, ProjectMeshAndUrdfFiles) {
  const std::vector<BadProject> cases = BadProjects();
  EXPECT_GE(cases.size(), 40u);
  const std::string plan = HalfStoolPlan().string();
  for (const BadProject& c : cases) {
    TempDir dir(c.name);
    WriteBlocksFiles(dir.path);
    json project = BlocksProject();
    if (c.edit) c.edit(project, dir.path);
    const fs::path file =
        WriteBytes(dir.path / (c.name + ".json"), c.edit ? project.dump(2) : c.raw);
    const fs::path out = dir.path / "out";
    fs::create_directories(out);
    const std::string p = file.string();
    std::vector<std::vector<std::string>> commands = {
        {"validate", p},
        {"info", p},
        {"preprocess", p, "-o", (out / "pre.json").string()},
        {"plan", p, "--task-only", "-o", (out / "plan.json").string()},
        {"sim", p, "--plan", plan, "-o", (out / "report.json").string()},
        {"validate", p, "--plan", plan},
    };
#ifdef WRAP_TEST_HAVE_RENDER
    commands.push_back({"render", p, "-o", (out / "render").string()});
#endif
    std::vector<std::string> phrases;
    for (const std::string& phrase : c.phrases) phrases.push_back(Named(phrase, project));
    for (const auto& args : commands) {
      const std::string what = c.name + ": wrap " + args[0];
      ExpectBadInput(Wrap(args), phrases, what);
    }
    ExpectNoOutput(out, c.name);
    for (const std::string& f : ListFiles(out / "render")) ADD_FAILURE() << c.name << ": " << f;
  }
}

/// One malformed plan file: how it breaks the half stool's plan, and the phrases stderr must hold.
struct BadPlan {
  std::string name;
  std::function<void(json&)> edit;
  std::vector<std::string> phrases;
  std::string raw;
};

// Every malformed plan file through every command that reads a plan.
TEST(MalformedInputs, PlanFiles) {
  const std::string good = ReadBytes(HalfStoolPlan());
  ASSERT_FALSE(good.empty());
  const std::vector<BadPlan> cases = {
      {"plan_empty", nullptr, {"plan_empty.json", "malformed JSON"}, " "},
      {"plan_not_json", nullptr, {"plan_not_json.json", "malformed JSON"}, "plan: yes"},
      {"plan_truncated",
       nullptr,
       {"plan_truncated.json", "malformed JSON"},
       good.substr(0, good.size() / 3)},
      {"plan_wrong_format",
       [](json& p) { p["format"] = "wrap-project"; },
       {"plan_wrong_format.json", "format", "wrap-plan"}},
      {"plan_newer_version",
       [](json& p) { p["version"] = 7; },
       {"plan_newer_version.json", "version"}},
      {"plan_no_actions",
       [](json& p) { p.erase("actions"); },
       {"plan_no_actions.json", "actions", "missing"}},
      {"plan_unknown_robot",
       [](json& p) { p["actions"][0]["robots"] = {"nobody"}; },
       {"plan_unknown_robot.json", "actions[0].robots[0]", "nobody"}},
      {"plan_unknown_action",
       [](json& p) { p["actions"][0]["type"] = "teleport"; },
       {"plan_unknown_action.json", "actions[0].type", "teleport"}},
      {"plan_short_joints",
       [](json& p) {
         p["actions"][0]["keyframe"]["q"]["left"] = {0, 0};
       },
       {"plan_short_joints.json", "actions[0].keyframe.q.left", "6 numbers"}},
      {"plan_joints_not_numbers",
       [](json& p) { p["actions"][0]["keyframe"]["q"]["left"] = "x"; },
       {"plan_joints_not_numbers.json", "actions[0].keyframe.q.left"}},
  };
  const std::string project = cli::Project("half_stool");
  for (const BadPlan& c : cases) {
    TempDir dir(c.name);
    std::string text = c.raw;
    if (c.edit) {
      json plan = json::parse(good);
      c.edit(plan);
      text = plan.dump(1);
    }
    const std::string file = WriteBytes(dir.path / (c.name + ".json"), text).string();
    const fs::path out = dir.path / "out";
    fs::create_directories(out);
    std::vector<std::vector<std::string>> commands = {
        {"validate", project, "--plan", file},
        {"sim", project, "--plan", file, "-o", (out / "report.json").string()},
    };
#ifdef WRAP_TEST_HAVE_RENDER
    commands.push_back({"render", project, "--plan", file, "-o", (out / "render").string()});
#endif
    for (const auto& args : commands) {
      ExpectBadInput(Wrap(args), c.phrases, c.name + ": wrap " + args[0]);
    }
    ExpectNoOutput(out, c.name);
    for (const std::string& f : ListFiles(out / "render")) ADD_FAILURE() << c.name << ": " << f;
  }
}

}  // namespace
}  // namespace wrap::reliability
