// The plan file (format "wrap-plan", version 1): writing, reading and checking a plan against the
// project it is meant for. Names, not indices, in the file: robots, parts and DAG nodes by name,
// so a plan read back against another project fails clearly instead of meaning something else.
//
//   {"format": "wrap-plan", "version": 1, "project": NAME,
//    "robots": [names], "parts": [names], "nodes": [names: parts, then steps],
//    "milestones": [step names],
//    "stats": {every PlanStats field by its name, "failure": text},
//    "initial": KEYFRAME,
//    "actions": [{"index": i, "type": "pick", "robots": [names], "objects": [node names],
//                 "grasps": [{"robot", "subassembly", "index", "part", "X_PG", "width_m"}],
//                 "placement": {"placement", "slot", "yaw"}      (place, when known),
//                 "milestone": m, "start_s": t0, "end_s": t1      (times once retimed),
//                 "keyframe": KEYFRAME, "approach": KEYFRAME      (assemble, when known),
//                 "description": "ur5e_a picks 'seat' (grasp 3)" (written, not read)}],
//    with motion:
//    "trajectories": [{"robot": name, "t": [...], "q": [[...]], "qd": [[...]],
//                      "opening_m": [...]}],
//    "segments": [{"kind": "free", "action": i, "robots": [names], "objects": [node names],
//                  "start_s": t0, "end_s": t1,
//                  "wait": "none|robot|object|collision", "wait_segment": k  (absent in
//                  plans written before the schedule recorded its waits)}],
//    "contacts": [...]}
//   KEYFRAME = {"q": {robot name: [joint values]},
//               "objects": [{"name": node name, "X_WA": POSE, "resting": bool}]}
//   POSE = {"xyz": [x, y, z], "rpy": [roll, pitch, yaw]}  (m, rad, as in project files)
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "core/result.h"
#include "model/assembly.h"
#include "model/project.h"
#include "task/plan.h"

namespace wrap {

/// The plan as JSON text (2-space indent, keys in a fixed order, doubles round-trippable, a
/// final newline). Indices that fall outside the plan's own name lists are written as "#i".
std::string SerializePlan(const Plan& plan);

/// Parses a plan file's text. `origin` names the document in messages (e.g. the file name).
/// Checks the structure fully: types, required fields, finite numbers, known and unique names,
/// index ranges, each action's robot, object and grasp counts for its type, joint vectors of one
/// size per robot. Fails with kInvalidInput as "ORIGIN: JSON.PATH: problem", e.g.
/// `plan.json: actions[3].keyframe.q.ur5e_a: expected 6 numbers, found 5`. Never throws.
Result<Plan> ParsePlan(std::string_view text, const std::string& origin);

/// Reads and parses a plan file. Fails with kIo when it cannot be read, else as ParsePlan.
Result<Plan> ReadPlanFile(const std::filesystem::path& path);

/// Writes the plan to `path` atomically. Fails with kIo naming the path.
[[nodiscard]] Result<void> SavePlan(const Plan& plan, const std::filesystem::path& path);

/// Checks that a parsed plan belongs to `project` (with its DAG `tree`): the same robots, parts
/// and nodes in the same order, milestones that are steps, joint vectors of each robot's chain
/// size (catalog models; URDF robots are not loaded here), grasps whose part lies in their
/// subassembly, and keyframes whose objects hold every part exactly once. Fails with
/// kInvalidInput as "PLAN_FILE: JSON.PATH: problem".
Result<void> CheckPlanMatchesProject(const Plan& plan, const Project& project,
                                     const AssemblyTree& tree, const std::string& plan_file);

}  // namespace wrap
