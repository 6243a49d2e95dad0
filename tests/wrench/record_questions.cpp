// wrap_record_wrench_questions OUT.jsonl [PER_PROJECT]: plans the example projects (task only)
// and writes a sample of the wrench questions their searches computed, one JSON object per line,
// for recorded_questions_test.cpp (tests/wrench/data/planner_questions.jsonl). Not a test: run it
// by hand when the planner's questions change shape.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <mutex>
#include <string>
#include <vector>

#include "grasp/preprocess.h"
#include "model/validate.h"
#include "question_json.h"
#include "task/planner.h"

namespace {

struct Source {
  const char* project;
  int seed;
};

// The projects of the paper's table and the scaling figure that Wrap has: two-finger and vacuum
// grippers, tables, connections, one and two held bodies.
constexpr Source kSources[] = {
    {"stool", 0},      {"stool", 1},        {"half_stool", 0},
    {"chair", 0},      {"cross", 0},        {"cube", 0},
    {"cube_2x2x3", 0}, {"fabrica_beam", 0}, {"fabrica_plumbers_block", 0}};

// The questions of one planning run, sorted by their text (the searches run on several threads,
// so the order they are asked in varies; the set does not).
std::vector<std::string> Record(const std::string& root, const Source& s) {
  const std::string file = root + "/projects/" + s.project + ".json";
  const wrap::LoadedProject lp = wrap::LoadProject(file);
  if (!lp.ok()) return {};
  wrap::RunContext ctx(static_cast<std::uint64_t>(s.seed));
  wrap::PreprocessOptions pre_options;
  pre_options.project_file = file;
  auto pre = wrap::Preprocess(*lp.project, lp.check, pre_options, ctx);
  if (!pre) return {};
  std::mutex mutex;
  std::vector<std::string> lines;
  const std::string source = std::string(s.project) + " seed " + std::to_string(s.seed);
  wrap::TaskPlannerOptions options;
  options.project_file = file;
  options.wrench_question_observer = [&](const wrap::StepConfiguration& c,
                                         const wrap::WrenchQuery& q) {
    const std::string line = wrap::WrenchQuestionToJson({c, q, source}).dump();
    std::lock_guard lock(mutex);
    lines.push_back(line);
  };
  auto plan = wrap::PlanTask(*lp.project, lp.check, *pre, options, ctx);
  if (!plan) std::cerr << source << ": " << plan.error().message << "\n";
  std::sort(lines.begin(), lines.end());
  lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
  return lines;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: wrap_record_wrench_questions OUT.jsonl [PER_PROJECT]\n";
    return 2;
  }
  const int per_project = argc > 2 ? std::max(1, std::atoi(argv[2])) : 40;
  std::ofstream out(argv[1]);
  long long total = 0;
  for (const Source& s : kSources) {
    const std::vector<std::string> lines = Record(WRAP_SOURCE_DIR, s);
    total += static_cast<long long>(lines.size());
    const int n = static_cast<int>(lines.size());
    const int keep = std::min(n, per_project);
    for (int k = 0; k < keep; ++k) out << lines[static_cast<size_t>(k) * n / keep] << "\n";
    std::cerr << s.project << " seed " << s.seed << ": " << n << " questions, " << keep
              << " kept\n";
  }
  std::cerr << total << " questions recorded\n";
  return out ? 0 : 1;
}
