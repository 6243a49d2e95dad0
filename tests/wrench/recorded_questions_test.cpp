// The dense simplex against Clp on real questions of the planner: wrench questions recorded from
// the example projects' searches (record_questions.cpp wrote data/planner_questions.jsonl). Both
// backends must give the same verdict and load factor; the planner's fast path (stop at the first
// failing vertex) the same verdict.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "question_json.h"

namespace wrap {
namespace {

std::vector<WrenchQuestion> LoadQuestions() {
  std::vector<WrenchQuestion> out;
  std::ifstream in(std::string(WRAP_SOURCE_DIR) + "/tests/wrench/data/planner_questions.jsonl");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    auto q = WrenchQuestionFromJson(nlohmann::json::parse(line));
    EXPECT_TRUE(q.has_value()) << "line " << number << ": " << (q ? "" : q.error().message);
    if (q) out.push_back(std::move(*q));
  }
  return out;
}

bool SameUtilisation(double a, double b) {
  if (std::isinf(a) || std::isinf(b)) return a == b;
  return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(b));
}

TEST(RecordedQuestions, DenseMatchesClpAndTheFastPathMatchesTheVerdict) {
  const std::vector<WrenchQuestion> questions = LoadQuestions();
  ASSERT_GE(questions.size(), 200u);
  WrenchChecker dense(WrenchOptions{});
  WrenchChecker clp(WrenchOptions{.backend = WrenchLpBackend::kClp});
  WrenchChecker fast(WrenchOptions{.first_failure_suffices = true});
  std::set<std::string> sources;
  std::set<int> gates;
  int feasible = 0, infeasible = 0, vacuum = 0, held_pairs = 0;
  for (const WrenchQuestion& q : questions) {
    const Result<WrenchCheck> a = dense.Check(q.config, q.query);
    const Result<WrenchCheck> b = clp.Check(q.config, q.query);
    const Result<WrenchCheck> f = fast.Check(q.config, q.query);
    ASSERT_TRUE(a && b && f) << q.source << ": " << (a ? "" : a.error().message)
                             << (b ? "" : b.error().message) << (f ? "" : f.error().message);
    EXPECT_EQ(a->feasible, b->feasible) << q.source << ": " << a->reason << " / " << b->reason;
    EXPECT_EQ(f->feasible, b->feasible) << q.source << ": " << f->reason;
    EXPECT_EQ(a->vertex_count, b->vertex_count) << q.source;
    EXPECT_EQ(a->failing_vertex_count, b->failing_vertex_count) << q.source;
    EXPECT_TRUE(SameUtilisation(a->utilisation, b->utilisation))
        << q.source << ": dense " << a->utilisation << ", Clp " << b->utilisation;
    sources.insert(q.source);
    gates.insert(static_cast<int>(q.query.gate));
    (b->feasible ? feasible : infeasible)++;
    for (const WrenchGripper& g : q.config.grippers) {
      if (g.kind == EndEffectorKind::kVacuum) {
        ++vacuum;
        break;
      }
    }
    if (q.config.bodies.size() > 1) ++held_pairs;
  }
  // The sample covers what the planner asks: several projects, every gate, both verdicts, vacuum
  // and two-finger grippers, questions about more than one body.
  EXPECT_GE(sources.size(), 8u);
  EXPECT_EQ(gates.size(), 4u);
  EXPECT_GT(feasible, 50);
  EXPECT_GT(infeasible, 20);
  EXPECT_GT(vacuum, 20);
  EXPECT_GT(held_pairs, 20);
}

}  // namespace
}  // namespace wrap
