// Wrench questions (a StepConfiguration and its WrenchQuery) as JSON, one object per line: how
// the planner's real questions are recorded (record_questions.cpp) and replayed against Clp
// (recorded_questions_test.cpp). Every number round-trips exactly; infinite bounds are written
// as the strings "inf" and "-inf".
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "core/result.h"
#include "wrench/wrench.h"

namespace wrap {

/// One recorded question.
struct WrenchQuestion {
  StepConfiguration config;  ///< The moment of the plan.
  WrenchQuery query;         ///< The gate and the mating mode.
  std::string source;        ///< Where it was asked, e.g. "stool seed 3".
};

/// The question as one JSON object.
nlohmann::json WrenchQuestionToJson(const WrenchQuestion& question);

/// The question of WrenchQuestionToJson; an error naming the field that is missing or wrong.
Result<WrenchQuestion> WrenchQuestionFromJson(const nlohmann::json& j);

}  // namespace wrap
