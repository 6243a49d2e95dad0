// libFuzzer target: ImportStep on bytes written as a .step file (see fuzz_targets.h).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return wrap::fuzz::FuzzStep(data, size);
}
