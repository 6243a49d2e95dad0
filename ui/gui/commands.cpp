#include "gui/commands.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "geometry/mesh_import.h"
#include "geometry/step_cache.h"
#include "model/catalog.h"
#include "model/step_parts.h"
#include "robot/urdf_import.h"

namespace wrap::gui {

namespace fs = std::filesystem;

namespace {

std::string Quote(const std::string& s) { return "'" + s + "'"; }

Part* FindPart(Project& p, const std::string& name) {
  for (Part& part : p.parts) {
    if (part.name == name) return &part;
  }
  return nullptr;
}

Robot* FindRobot(Project& p, const std::string& name) {
  for (Robot& robot : p.robots) {
    if (robot.name == name) return &robot;
  }
  return nullptr;
}

/// The step that has `name` as an input, or nullptr.
const Step* ConsumerOf(const Project& p, const std::string& name) {
  for (const Step& step : p.steps) {
    if (std::find(step.inputs.begin(), step.inputs.end(), name) != step.inputs.end()) return &step;
  }
  return nullptr;
}

std::unexpected<Error> Refuse(std::string message) {
  return Fail(ErrorCode::kInvalidInput, std::move(message));
}

Result<void> CheckNewName(const Project& p, const std::string& name, const std::string& old) {
  if (name.empty()) return Refuse("a name cannot be empty");
  if (name != old && NameTaken(p, name)) {
    return Refuse("the name " + Quote(name) + " is already used by a part or a step");
  }
  return {};
}

void RenameReferences(Project& p, const std::string& old_name, const std::string& new_name) {
  for (Step& step : p.steps) {
    for (std::string& input : step.inputs) {
      if (input == old_name) input = new_name;
    }
    if (step.mating.moved == old_name) step.mating.moved = new_name;
    if (step.mating.base == old_name) step.mating.base = new_name;
  }
}

void DropInput(Step& step, const std::string& input) {
  std::erase(step.inputs, input);
  if (step.mating.moved == input) step.mating.moved.clear();
  if (step.mating.base == input) step.mating.base.clear();
}

/// `file` as a project writes it: relative to the folder of `project_file` where it can be.
std::string ProjectRelativePath(const fs::path& project_file, const fs::path& file) {
  const fs::path dir = fs::absolute(project_file).parent_path();
  const fs::path absolute = fs::absolute(file).lexically_normal();
  const fs::path relative = absolute.lexically_relative(dir);
  return relative.empty() ? absolute.string() : relative.generic_string();
}

/// Where an imported part with bounding box `box` goes: on the table, in a row along +y beside
/// the parts already there, its box's centre over the spot, its lowest point on the top.
Vec3 NextInRow(const Project& project, const Aabb& box) {
  const double spacing = std::max(0.12, 1.2 * std::max(box.size().x(), box.size().y()));
  const double row = -0.5 * project.table.size.y() + spacing;
  const double y = row + spacing * static_cast<double>(project.parts.size());
  const Vec3 centre = 0.5 * (box.min + box.max);
  return Vec3(project.table.center_xy.x() - centre.x(),
              project.table.center_xy.y() + y - centre.y(), project.table.height - box.min.z());
}

Result<void> CheckCatalog(const Robot& robot) {
  if (robot.urdf.empty() && !FindRobotModel(robot.model)) {
    return Refuse("robot model " + Quote(robot.model) + " is not in the catalog (" +
                  RobotModelNames() + ")");
  }
  if (!FindEndEffector(robot.end_effector)) {
    return Refuse("end effector " + Quote(robot.end_effector) + " is not in the catalog (" +
                  EndEffectorNames() + ")");
  }
  return {};
}

}  // namespace

bool NameTaken(const Project& project, const std::string& name) {
  for (const Part& part : project.parts) {
    if (part.name == name) return true;
  }
  return FindStep(project, name) != nullptr;
}

std::string UniqueName(const Project& project, const std::string& base) {
  if (!NameTaken(project, base)) return base;
  for (int i = 2;; ++i) {
    std::string name = base + "_" + std::to_string(i);
    if (!NameTaken(project, name)) return name;
  }
}

// ---- Parts ----------------------------------------------------------------------------------

Command AddPart(Part part) {
  const std::string label = "add part " + Quote(part.name);
  return {label, "", [part](Project& p) -> Result<void> {
            if (auto ok = CheckNewName(p, part.name, ""); !ok) return ok;
            p.parts.push_back(part);
            return {};
          }};
}

Command AddParts(std::vector<Part> parts) {
  const std::string label = parts.size() == 1 ? "add part " + Quote(parts.front().name)
                                              : "add " + std::to_string(parts.size()) + " parts";
  return {label, "", [parts](Project& p) -> Result<void> {
            Project next = p;
            for (const Part& part : parts) {
              if (auto ok = CheckNewName(next, part.name, ""); !ok) return ok;
              next.parts.push_back(part);
            }
            p = std::move(next);
            return {};
          }};
}

Command RemovePart(const std::string& name) {
  return {"remove part " + Quote(name), "", [name](Project& p) -> Result<void> {
            auto it = std::find_if(p.parts.begin(), p.parts.end(),
                                   [&](const Part& part) { return part.name == name; });
            if (it == p.parts.end()) return Refuse("there is no part " + Quote(name));
            if (const Step* step = ConsumerOf(p, name)) {
              return Refuse("part " + Quote(name) + " is an input of step " + Quote(step->name) +
                            ": remove it from the step first");
            }
            p.parts.erase(it);
            return {};
          }};
}

Command SetPart(const std::string& name, Part part, std::string merge_key) {
  return {"edit part " + Quote(name), std::move(merge_key),
          [name, part](Project& p) -> Result<void> {
            Part* old = FindPart(p, name);
            if (!old) return Refuse("there is no part " + Quote(name));
            if (auto ok = CheckNewName(p, part.name, name); !ok) return ok;
            *old = part;
            if (part.name != name) RenameReferences(p, name, part.name);
            return {};
          }};
}

const std::vector<MeshUnit>& MeshUnits() {
  static const std::vector<MeshUnit> units = {
      {"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"inch", 0.0254}};
  return units;
}

Result<Part> PreparePartImport(const Project& project, const fs::path& project_file,
                               const fs::path& mesh_file, const PartImportOptions& options) {
  if (!(options.scale > 0.0) || !std::isfinite(options.scale)) {
    return Refuse("import: the scale must be a positive number");
  }
  MeshImportOptions import;
  import.scale = options.scale;
  auto mesh = ImportMesh(mesh_file, import);
  if (!mesh) return std::unexpected(mesh.error());
  const Aabb box = ComputeAabb(*mesh);

  Part part;
  part.name = UniqueName(
      project, mesh_file.stem().string().empty() ? std::string("part") : mesh_file.stem().string());
  part.mesh = ProjectRelativePath(project_file, mesh_file);
  part.scale = options.scale;
  part.mass_kg = options.mass_kg;
  part.density_kg_m3 = options.density_kg_m3;
  part.color = options.color.value_or(NewPartColor(project.parts.size()));
  part.initial_pose.xyz = NextInRow(project, box);
  return part;
}

Result<std::vector<Part>> PrepareStepImport(const Project& project, const fs::path& project_file,
                                            const fs::path& step_file) {
  auto load = LoadStep(step_file, {.tessellation = project.tessellation,
                                   .cache_dir = StepCacheDirFor(fs::absolute(project_file))});
  if (!load) return std::unexpected(load.error());
  const StepAssembly& assembly = *load->assembly;
  const std::string mesh = ProjectRelativePath(project_file, step_file);
  if (assembly.instances.size() > 1) return PartsFromStep(assembly, project, {.mesh = mesh});
  // One solid: a part like an imported mesh, but with the file's name and colour.
  Part part;
  part.name = UniqueName(
      project, step_file.stem().string().empty() ? std::string("part") : step_file.stem().string());
  part.mesh = mesh;
  part.color = assembly.instances.front().color ? Rgba(*assembly.instances.front().color)
                                                : NewPartColor(project.parts.size());
  part.initial_pose.xyz = NextInRow(project, ComputeAabb(MergedInstances(assembly)));
  return std::vector<Part>{part};
}

// ---- Steps ----------------------------------------------------------------------------------

Command AddStep(const std::string& name) {
  return {"add step " + Quote(name), "", [name](Project& p) -> Result<void> {
            if (auto ok = CheckNewName(p, name, ""); !ok) return ok;
            Step step;
            step.name = name;
            p.steps.push_back(step);
            return {};
          }};
}

Command RemoveStep(const std::string& name) {
  return {"remove step " + Quote(name), "", [name](Project& p) -> Result<void> {
            auto it = std::find_if(p.steps.begin(), p.steps.end(),
                                   [&](const Step& s) { return s.name == name; });
            if (it == p.steps.end()) return Refuse("there is no step " + Quote(name));
            p.steps.erase(it);
            for (Step& step : p.steps) DropInput(step, name);
            return {};
          }};
}

Command RenameNode(const std::string& old_name, const std::string& new_name) {
  return {"rename " + Quote(old_name) + " to " + Quote(new_name), "",
          [old_name, new_name](Project& p) -> Result<void> {
            Part* part = FindPart(p, old_name);
            Step* step = FindStep(p, old_name);
            if (!part && !step) return Refuse("there is no part or step " + Quote(old_name));
            if (auto ok = CheckNewName(p, new_name, old_name); !ok) return ok;
            if (part) part->name = new_name;
            if (step) step->name = new_name;
            RenameReferences(p, old_name, new_name);
            return {};
          }};
}

Result<void> CheckNewInput(const Project& p, const std::string& step_name,
                           const std::string& input) {
  const Step* step = FindStep(p, step_name);
  if (!step) return Refuse("there is no step " + Quote(step_name));
  if (!NameTaken(p, input)) return Refuse("there is no part or step " + Quote(input));
  if (input == step_name) {
    return Refuse("step " + Quote(step_name) + " cannot be an input of itself");
  }
  if (std::find(step->inputs.begin(), step->inputs.end(), input) != step->inputs.end()) {
    return Refuse(Quote(input) + " is already an input of step " + Quote(step_name));
  }
  if (step->inputs.size() >= 2) {
    return Refuse("step " + Quote(step_name) +
                  " already joins two inputs: remove one before adding " + Quote(input));
  }
  if (const Step* other = ConsumerOf(p, input)) {
    return Refuse(Quote(input) + " is already an input of step " + Quote(other->name) +
                  ": a subassembly is used by one step only");
  }
  // A cycle: `step_name` is among the inputs of `input`, transitively. Walk down from `input`
  // and keep the chain for the message.
  std::vector<std::string> chain;
  std::function<bool(const std::string&)> reaches = [&](const std::string& node) {
    const Step* s = FindStep(p, node);
    if (!s) return false;
    for (const std::string& in : s->inputs) {
      if (in == step_name || reaches(in)) {
        chain.push_back(in);
        return true;
      }
    }
    return false;
  };
  if (reaches(input)) {
    std::string path = Quote(step_name);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      if (*it != step_name) path = Quote(*it) + " <- " + path;
    }
    return Refuse("making " + Quote(input) + " an input of " + Quote(step_name) +
                  " would make a cycle: " + Quote(step_name) + " is already built into " +
                  Quote(input) + " (" + path + " <- " + Quote(input) + ")");
  }
  return {};
}

Command AddInput(const std::string& step_name, const std::string& input) {
  return {"make " + Quote(input) + " an input of " + Quote(step_name), "",
          [step_name, input](Project& p) -> Result<void> {
            if (auto ok = CheckNewInput(p, step_name, input); !ok) return ok;
            Step* step = FindStep(p, step_name);
            step->inputs.push_back(input);
            if (step->mating.base.empty() && step->mating.moved != input) {
              step->mating.base = input;
            } else if (step->mating.moved.empty() && step->mating.base != input) {
              step->mating.moved = input;
            }
            return {};
          }};
}

Command RemoveInput(const std::string& step_name, const std::string& input) {
  return {"remove input " + Quote(input) + " of " + Quote(step_name), "",
          [step_name, input](Project& p) -> Result<void> {
            Step* step = FindStep(p, step_name);
            if (!step) return Refuse("there is no step " + Quote(step_name));
            if (std::find(step->inputs.begin(), step->inputs.end(), input) == step->inputs.end()) {
              return Refuse(Quote(input) + " is not an input of step " + Quote(step_name));
            }
            DropInput(*step, input);
            return {};
          }};
}

Command SetMating(const std::string& step_name, Mating mating, std::string merge_key) {
  return {"edit the mating of " + Quote(step_name), std::move(merge_key),
          [step_name, mating](Project& p) -> Result<void> {
            Step* step = FindStep(p, step_name);
            if (!step) return Refuse("there is no step " + Quote(step_name));
            auto is_input = [&](const std::string& n) {
              return n.empty() ||
                     std::find(step->inputs.begin(), step->inputs.end(), n) != step->inputs.end();
            };
            if (!is_input(mating.moved)) {
              return Refuse("moved input " + Quote(mating.moved) + " is not an input of " +
                            Quote(step_name));
            }
            if (!is_input(mating.base)) {
              return Refuse("base input " + Quote(mating.base) + " is not an input of " +
                            Quote(step_name));
            }
            if (!mating.moved.empty() && mating.moved == mating.base) {
              return Refuse("the moved and the base input must differ");
            }
            step->mating = mating;
            return {};
          }};
}

// ---- Robots ---------------------------------------------------------------------------------

namespace {

/// The corners of the table in turn, facing its centre.
void PlaceAtNextCorner(const Project& p, Robot& robot) {
  const int k = static_cast<int>(p.robots.size()) % 4;
  const double sx = (k == 0 || k == 3) ? 1.0 : -1.0;
  const double sy = k < 2 ? 1.0 : -1.0;
  const double hx = 0.5 * p.table.size.x() - 0.15, hy = 0.5 * p.table.size.y() - 0.15;
  robot.base_pose.xyz =
      Vec3(p.table.center_xy.x() + sx * hx, p.table.center_xy.y() + sy * hy, p.table.height);
  robot.base_pose.rpy = Vec3(0, 0, std::atan2(-sy * hy, -sx * hx));
}

/// `base`, or `base` followed by "_2", "_3", ...: the first robot name not taken.
std::string UniqueRobotName(const Project& p, const std::string& base, bool number_first) {
  auto taken = [&](const std::string& name) {
    return std::any_of(p.robots.begin(), p.robots.end(),
                       [&](const Robot& r) { return r.name == name; });
  };
  if (!number_first && !taken(base)) return base;
  for (int i = number_first ? 1 : 2;; ++i) {
    const std::string name = base + "_" + std::to_string(i);
    if (!taken(name)) return name;
  }
}

}  // namespace

Command AddRobot(const std::string& model, const std::string& end_effector) {
  return {"add robot " + Quote(model), "", [model, end_effector](Project& p) -> Result<void> {
            Robot robot;
            robot.model = model;
            robot.end_effector = end_effector;
            if (auto ok = CheckCatalog(robot); !ok) return ok;
            robot.name = UniqueRobotName(p, model, true);
            PlaceAtNextCorner(p, robot);
            p.robots.push_back(robot);
            return {};
          }};
}

Result<Robot> PrepareUrdfRobot(const Project& project, const fs::path& project_file,
                               const fs::path& urdf_file, const std::string& root,
                               const std::string& tip, const std::string& end_effector) {
  if (!FindEndEffector(end_effector)) {
    return Refuse("end effector " + Quote(end_effector) + " is not in the catalog (" +
                  EndEffectorNames() + ")");
  }
  UrdfImportOptions options;
  options.root = root;
  options.tip = tip;
  options.import_visual = false;  // checked here; the cell loads the visuals when it is built
  auto chain = ImportUrdf(urdf_file, options);
  if (!chain) return std::unexpected(chain.error());
  Robot robot;
  const std::string stem = urdf_file.stem().string();
  robot.name = UniqueRobotName(project, stem.empty() ? std::string("robot") : stem, false);
  const fs::path dir = fs::absolute(project_file).parent_path();
  const fs::path absolute = fs::absolute(urdf_file).lexically_normal();
  const fs::path relative = absolute.lexically_relative(dir);
  robot.urdf = relative.empty() ? absolute.string() : relative.generic_string();
  robot.urdf_root = root;
  robot.urdf_tip = tip;
  robot.end_effector = end_effector;
  PlaceAtNextCorner(project, robot);
  return robot;
}

Command AddRobot(Robot robot) {
  return {"add robot " + Quote(robot.name), "", [robot](Project& p) -> Result<void> {
            if (robot.name.empty()) return Refuse("a robot name cannot be empty");
            if (FindRobot(p, robot.name)) {
              return Refuse("there is already a robot " + Quote(robot.name));
            }
            if (auto ok = CheckCatalog(robot); !ok) return ok;
            p.robots.push_back(robot);
            return {};
          }};
}

Command RemoveRobot(const std::string& name) {
  return {"remove robot " + Quote(name), "", [name](Project& p) -> Result<void> {
            auto it = std::find_if(p.robots.begin(), p.robots.end(),
                                   [&](const Robot& r) { return r.name == name; });
            if (it == p.robots.end()) return Refuse("there is no robot " + Quote(name));
            p.robots.erase(it);
            return {};
          }};
}

Command SetRobot(const std::string& name, Robot robot, std::string merge_key) {
  return {"edit robot " + Quote(name), std::move(merge_key),
          [name, robot](Project& p) -> Result<void> {
            Robot* old = FindRobot(p, name);
            if (!old) return Refuse("there is no robot " + Quote(name));
            if (robot.name.empty()) return Refuse("a robot name cannot be empty");
            if (robot.name != name && FindRobot(p, robot.name)) {
              return Refuse("there is already a robot " + Quote(robot.name));
            }
            if (auto ok = CheckCatalog(robot); !ok) return ok;
            *old = robot;
            return {};
          }};
}

Command SetWrenchLimits(const std::string& robot_name, std::optional<WrenchLimits> limits,
                        std::string merge_key) {
  const std::string label = robot_name.empty() ? std::string("edit the wrench limits")
                                               : "edit the wrench limits of " + Quote(robot_name);
  return {label, std::move(merge_key), [robot_name, limits](Project& p) -> Result<void> {
            if (robot_name.empty()) {
              if (!limits) return Refuse("the project's wrench limits cannot be removed");
              p.wrench_limits = *limits;
              return {};
            }
            Robot* robot = FindRobot(p, robot_name);
            if (!robot) return Refuse("there is no robot " + Quote(robot_name));
            robot->wrench_limits = limits;
            return {};
          }};
}

// ---- Project-wide ---------------------------------------------------------------------------

Command SetProjectInfo(std::string name, std::string description) {
  return {"edit the project's name and description", "project:info",
          [name, description](Project& p) -> Result<void> {
            p.name = name;
            p.description = description;
            return {};
          }};
}

Command SetTable(Table table, std::string merge_key) {
  return {"edit the table", std::move(merge_key), [table](Project& p) -> Result<void> {
            p.table = table;
            return {};
          }};
}

Command SetPlannerDefaults(PlannerDefaults planner, std::string merge_key) {
  return {"edit the planner defaults", std::move(merge_key), [planner](Project& p) -> Result<void> {
            p.planner = planner;
            return {};
          }};
}

Command SetConnectionLimits(WrenchBox limits, std::string merge_key) {
  return {"edit the connection limits", std::move(merge_key), [limits](Project& p) -> Result<void> {
            p.connection_limits = limits;
            return {};
          }};
}

}  // namespace wrap::gui
