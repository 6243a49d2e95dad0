// libFuzzer target: STEP import in this process on bytes written as a .step file (see
// fuzz_targets.h): OpenCASCADE's own crashes are findings too (wrap imports in a child process).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return wrap::fuzz::FuzzStep(data, size, wrap::fuzz::StepProcess::kThisProcess);
}
