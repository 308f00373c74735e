// Fuzzes the Gmsh MSH 4.1 reader (config/models/*.msh, users' own meshes): any file must
// read or throw config::ConfigError — no crash, no UB, no unbounded allocation — and every
// element of a file that reads has as many node tags as its type needs.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "common/config_error.h"
#include "model/msh_reader.h"

using namespace sedbridge;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 200000) return 0;
  // The reader takes a path: one scratch file per fuzzing process.
  static const std::string path = "/tmp/sedbridge_fuzz_msh_" + std::to_string(::getpid()) + ".msh";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const model::MshFile m = model::ReadMshFile(path);
    for (const auto& e : m.elements) {
      if (static_cast<int>(e.node_tags.size()) != model::MshNodesPerElement(e.type)) std::abort();
    }
  } catch (const config::ConfigError&) {
  }
  std::remove(path.c_str());  // nothing left behind when fuzzing stops
  return 0;
}
