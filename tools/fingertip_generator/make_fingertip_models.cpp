// make_fingertip_models: builds the parametric fingertip meshes from model YAMLs.
//
//   make_fingertip_models config/models/B.yaml [more.yaml ...] [--out-dir DIR]
//   make_fingertip_models --all [--out-dir DIR]    # every config/models/*.yaml with geometry
//
// Each YAML's `mesh` key names the .msh to write (relative to the YAML); with --out-dir the
// file goes to DIR under the same file name instead (used by the regeneration test).
// Meshing is deterministic (one thread, fixed seed), so the committed files are reproduced.

#include <gmsh.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "common/config_error.h"
#include "common/resource_path.h"
#include "model/model_description.h"
#include "tools/fingertip_generator/fingertip_mesher.h"

namespace sedbridge::tools {
namespace {

namespace fs = std::filesystem;

int Usage() {
  std::fprintf(stderr,
               "usage: make_fingertip_models (MODEL.yaml ... | --all) [--out-dir DIR]\n"
               "  Builds each model's .msh (Gmsh MSH 4.1) from its geometry/layers/mesh_size.\n");
  return 2;
}

// Returns false (and says why) for YAMLs that describe no generated geometry, e.g. a
// user's CT mesh.
bool GenerateOne(const std::string& yaml_path, const std::string& out_dir) {
  // The loader's strict reader: a typo anywhere in the YAML stops generation too.
  const model::ModelDescription d = model::ReadModelDescription(yaml_path);
  if (!d.has_geometry) {
    std::printf("%s: no geometry/layers/mesh_size, skipped\n", yaml_path.c_str());
    return false;
  }
  const std::string& name = d.name;
  const model::FingertipGeometry& geometry = d.geometry;
  const std::string mesh = fs::path(d.mesh_path).filename().string();
  const fs::path msh_path = out_dir.empty() ? fs::path(d.mesh_path) : fs::path(out_dir) / mesh;
  const MeshStats s = MeshFingertip(geometry, name, msh_path.string());
  std::printf("%s -> %s: soft %d nodes / %d tets (epidermis %d, dermis %d, subcutaneous %d), "
              "rigid %d tets (bone %d, nail %d), stratum corneum %d triangles\n",
              name.c_str(), msh_path.string().c_str(), s.soft_nodes, s.soft_tets,
              s.tets_per_group[0], s.tets_per_group[1], s.tets_per_group[2], s.rigid_tets,
              s.tets_per_group[3], s.tets_per_group[4], s.stratum_corneum_triangles);
  return true;
}

int Main(int argc, char** argv) {
  std::vector<std::string> yamls;
  std::string out_dir;
  bool all = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--all") {
      all = true;
    } else if (arg == "--out-dir" && i + 1 < argc) {
      out_dir = argv[++i];
    } else if (arg == "-h" || arg == "--help" || (!arg.empty() && arg[0] == '-')) {
      return Usage();
    } else {
      yamls.push_back(arg);
    }
  }
  if (all) {
    const fs::path dir = fs::path(config::SourceRoot()) / "config" / "models";
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().extension() == ".yaml") yamls.push_back(entry.path().string());
    }
    std::sort(yamls.begin(), yamls.end());
  }
  if (yamls.empty()) return Usage();
  if (!out_dir.empty()) fs::create_directories(out_dir);

  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 1);
  gmsh::option::setNumber("General.Verbosity", 2);  // warnings and errors only
  int status = 0;
  for (const auto& y : yamls) {
    try {
      GenerateOne(y, out_dir);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "make_fingertip_models: %s: %s\n", y.c_str(), e.what());
      status = 1;
    } catch (const std::string& e) {  // the Gmsh API throws its last error message
      std::fprintf(stderr, "make_fingertip_models: %s: Gmsh: %s\n", y.c_str(), e.c_str());
      status = 1;
    }
  }
  gmsh::finalize();
  return status;
}

}  // namespace
}  // namespace sedbridge::tools

int main(int argc, char** argv) { return sedbridge::tools::Main(argc, argv); }
