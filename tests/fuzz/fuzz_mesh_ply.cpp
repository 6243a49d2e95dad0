// libFuzzer target: ImportMesh on bytes written as a .ply file (see fuzz_targets.h).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return wrap::fuzz::FuzzMesh(data, size, ".ply");
}
