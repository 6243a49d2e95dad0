// libFuzzer target: project JSON parsing and validation (see fuzz_targets.h).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return wrap::fuzz::FuzzProjectJson(data, size);
}
