#include "task/wrench_model.h"

#include <algorithm>

namespace wrap {

StepConfiguration BuildWrenchConfig(const TaskWorld& world, const TaskTables& tables,
                                    std::span<const WrenchObject> objects, int mating_step) {
  StepConfiguration config;
  std::vector<int> body_of(world.num_parts, -1);
  std::vector<const WrenchObject*> object_of(world.num_parts, nullptr);
  for (const WrenchObject& o : objects) {
    for (int p : world.tree->nodes[o.node].parts) {
      body_of[p] = static_cast<int>(config.bodies.size());
      object_of[p] = &o;
      config.bodies.push_back(
          {world.project->parts[p].name, world.part_mass[p], o.X_WA * world.part_com_A[p]});
    }
  }
  for (const WrenchObject& o : objects) {
    for (int step : world.subtree_steps[o.node]) {
      const StepInterface& s = world.interface(step);
      WrenchConnection c;
      c.body_a = body_of[s.part_moved];
      c.body_b = body_of[s.part_base];
      c.X_WC = o.X_WA * s.X_AC;
      c.limits = s.connection;
      if (c.body_a < 0 || c.body_b < 0 || c.body_a == c.body_b) continue;
      config.connections.push_back(std::move(c));
    }
    for (const auto& [robot, grasp_id] : o.holders) {
      const GraspRef& g = tables.grasp(grasp_id);
      const TaskRobot& r = world.robots[robot];
      const Iso3 X_WG = o.X_WA * world.X_AP[g.part] * g.X_PG;
      config.grippers.push_back(MakeGripper(r.name, body_of[g.part], X_WG, r.end_effector.kind,
                                            GraspLimits(r.limits, g.torque_scale)));
    }
    if (o.resting) {
      for (auto& [part, points] : TableContacts(world, o.node, o.X_WA)) {
        WrenchTableSupport t;
        t.body = body_of[part];
        t.p_WV = std::move(points);
        t.friction = world.project->table.friction;
        config.tables.push_back(std::move(t));
      }
    }
  }
  if (mating_step >= 0) {
    const StepInterface& s = world.interface(mating_step);
    const WrenchObject* base = object_of[s.part_base];
    if (body_of[s.part_moved] >= 0 && base != nullptr) {
      config.mating = MatingLoadFromProject(*s.mating, base->X_WA, body_of[s.part_moved],
                                            body_of[s.part_base], base->X_WA * s.p_A);
    }
  }
  return config;
}

}  // namespace wrap
