// The edits of a project, as Commands for Document::Execute. Each factory checks what it can
// when it runs (the project may have changed since the command was made) and refuses an edit
// that would break the project's structure with kInvalidInput and a message in words: a name
// used twice, an input that would make a cycle, an unknown robot model. Field values (a
// negative mass, a zero axis) are left to validation, which shows them with their JSON path.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "core/result.h"
#include "gui/document.h"
#include "model/project.h"

namespace wrap::gui {

// ---- Parts ----------------------------------------------------------------------------------

/// Adds `part` (its name must be new among parts and steps).
Command AddPart(Part part);
/// Adds `parts` as one edit (one undo step); refused, adding none, when a name is taken.
Command AddParts(std::vector<Part> parts);
/// Removes the part; refused while it is an input of a step (the message names the step).
Command RemovePart(const std::string& name);
/// Replaces the part `name` by `part`; a new name is carried into every step that refers to it.
/// `merge_key` merges consecutive edits of one field (e.g. "part:leg1:color").
Command SetPart(const std::string& name, Part part, std::string merge_key = "");

/// Mesh units offered at import, with their scale to metres.
struct MeshUnit {
  const char* name;  ///< "m", "cm", "mm", "inch".
  double scale;      ///< Metres per unit.
};
/// The units offered at import, metres first.
const std::vector<MeshUnit>& MeshUnits();

/// Options of PreparePartImport.
struct PartImportOptions {
  double scale = 1.0;             ///< Mesh units to metres.
  std::optional<double> mass_kg;  ///< Given mass; absent: density times volume.
  double density_kg_m3 = 1240.0;  ///< Density (PLA) when the mass is absent.
  std::optional<Rgba> color;      ///< Colour; absent: one from a palette by part count.
};

/// A part for `mesh_file` ready for AddPart: named after the file (made unique), its mesh path
/// written relative to the folder of `project_file`, resting on the table beside the parts
/// already there (its lowest point at the table height). Reads the mesh to check it and to
/// find its size. Fails with kIo or kInvalidInput naming the file (missing, not a mesh).
Result<Part> PreparePartImport(const Project& project, const std::filesystem::path& project_file,
                               const std::filesystem::path& mesh_file,
                               const PartImportOptions& options);

/// Parts for the STEP file `step_file`, ready for AddParts: one part for a file with one solid
/// (the whole file, named after it, placed like PreparePartImport places a mesh), one per
/// instance for an assembly (PartsFromStep: names, colours, assembled poses and shared meshes
/// from the file, resting on the table). The path is written relative to the folder of
/// `project_file`; the file is read through the tessellation cache beside the project. Fails
/// with kIo or kInvalidInput naming the file.
Result<std::vector<Part>> PrepareStepImport(const Project& project,
                                            const std::filesystem::path& project_file,
                                            const std::filesystem::path& step_file);

// ---- Assembly steps (the DAG) -----------------------------------------------------------------

/// Adds a step `name` without inputs (the name must be new among parts and steps).
Command AddStep(const std::string& name);
/// Removes the step; the step that used it as an input loses that input.
Command RemoveStep(const std::string& name);
/// Renames a part or a step, and every reference to it (inputs, matings).
Command RenameNode(const std::string& old_name, const std::string& new_name);
/// Makes `input` (a part or step) an input of `step`. Refused when the step has two inputs
/// already, `input` is the input of another step, or it would make a cycle (the message names
/// the chain of steps). Fills the mating's base (first input) and moved (second) when empty.
Command AddInput(const std::string& step, const std::string& input);
/// Removes `input` from the inputs of `step` (and from its mating's moved/base).
Command RemoveInput(const std::string& step, const std::string& input);
/// Sets the mating of `step`; moved and base must be empty or inputs of the step.
Command SetMating(const std::string& step, Mating mating, std::string merge_key = "");
/// Why `input` cannot become an input of `step`, or nothing when it can.
Result<void> CheckNewInput(const Project& project, const std::string& step,
                           const std::string& input);

// ---- Robots -----------------------------------------------------------------------------------

/// Adds a robot of catalog `model` with catalog `end_effector`, named "<model>_<n>", its base on
/// the table edge at the next free corner. Refused for names not in the catalog.
Command AddRobot(const std::string& model, const std::string& end_effector);
/// A robot from the user's URDF `urdf_file`, ready for AddRobot: its chain from link `root` to
/// link `tip` (empty: the URDF's root, its one tip; see ImportUrdf), end effector `end_effector`
/// from the catalog, named after the file (made unique among the robots), the path written
/// relative to the folder of `project_file`, its base at the next free table corner. Reads the
/// URDF (and its meshes) to check it: fails with kIo or kInvalidInput naming the file and the
/// problem (missing, malformed, no serial chain, an unknown end effector).
Result<Robot> PrepareUrdfRobot(const Project& project, const std::filesystem::path& project_file,
                               const std::filesystem::path& urdf_file, const std::string& root,
                               const std::string& tip, const std::string& end_effector);
/// Adds a prepared robot (e.g. from PrepareUrdfRobot). Refused for a name taken or a model or
/// end effector not in the catalog.
Command AddRobot(Robot robot);
/// Removes the robot.
Command RemoveRobot(const std::string& name);
/// Replaces the robot `name` by `robot` (name unique; model and end effector from the catalog
/// unless it is a URDF robot).
Command SetRobot(const std::string& name, Robot robot, std::string merge_key = "");
/// Sets the project's wrench limits (`robot` empty) or one robot's override (absent `limits`:
/// the robot uses the project's again).
Command SetWrenchLimits(const std::string& robot, std::optional<WrenchLimits> limits,
                        std::string merge_key = "");

// ---- Project-wide -----------------------------------------------------------------------------

/// Sets the name and description.
Command SetProjectInfo(std::string name, std::string description);
/// Sets the table.
Command SetTable(Table table, std::string merge_key = "");
/// Sets the planner defaults.
Command SetPlannerDefaults(PlannerDefaults planner, std::string merge_key = "");
/// Sets the project's default connection limits T_pq.
Command SetConnectionLimits(WrenchBox limits, std::string merge_key = "");

/// True when `name` is a part or a step of `project`.
bool NameTaken(const Project& project, const std::string& name);
/// `base`, or `base` followed by "_2", "_3", ... : the first name not taken.
std::string UniqueName(const Project& project, const std::string& base);

}  // namespace wrap::gui
