// Prints the fidelity table of docs/bridge-fidelity.md:
//   build/tools/bridge_fidelity_study/bridge_fidelity_study [MODEL [lumped|consistent [pitch_mm ...]]]   (default: B lumped 1 2 4)

#include <cstdio>
#include <cstdlib>
#include <string>

#include "bridge/scene_fe_step.h"
#include "bridge_fidelity.h"

int main(int argc, char** argv) {
  using namespace sedbridge::bridge;
  SetFeThreads(1);
  const std::string model = argc > 1 ? argv[1] : "B";
  const NodalLoad load = argc > 2 && std::string(argv[2]) == "consistent" ? NodalLoad::kConsistent : NodalLoad::kLumped;
  std::vector<double> pitches;
  for (int i = 3; i < argc; ++i) pitches.push_back(std::atof(argv[i]));
  if (pitches.empty()) pitches = {1, 2, 4};
  std::printf("| case | pitch [mm] | taxels | contact force [N] | BC force [N] | max SED ref [Pa] | max SED BC [Pa] | "
              "rel. L2 error | peak ratio | exact nodal forces: rel. L2 error |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& c : fidelity::DefaultCases())
    for (const auto& r : fidelity::RunCase(model, c, pitches, load)) {
      std::printf("| %s | %g | %d | %.3f | %.3f | %.1f | %.1f | %.3f | %.3f | %.3f |\n", r.name.c_str(), r.pitch_mm, r.taxels,
                  r.contact_force_N, r.bc_force_N, r.ref_max_sed_Pa, r.bc_max_sed_Pa, r.rel_l2_error, r.peak_ratio, r.exact_nodal_rel_l2_error);
      std::fflush(stdout);
    }
  return 0;
}
