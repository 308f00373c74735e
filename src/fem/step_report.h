#pragma once
// What one FE step reports: solver iterations, residual, convergence and stage times. Its own
// header so that callers that only read a step's report (the bridge's FE-step interface) need
// not include the FE engine (fem/simulation.h).

#include "common/stage_times.h"

namespace sedbridge::fem {

struct StepReport {
  double t_s = 0;
  int newton_iterations = 0;
  int linear_iterations = 0;     ///< summed over Newton iterations
  double linear_residual = 0;    ///< worst relative residual
  int solver_fallbacks = 0;      ///< PCG fallbacks to the direct solver in this step
  int tangent_fallbacks = 0;     ///< Newton iterations whose exact tangent did not factorize
                                 ///< and were solved with the definite one (UseDefiniteJacobian)
  bool converged = true;         ///< linear solves and (quasi-static) Newton converged
  int inverted_elements = 0;     ///< det F <= 0 at the end of the step
  double max_step_m = 0;         ///< max |dx| of the last Newton iteration
  bool finite = true;            ///< state is free of NaN/Inf (else it was rolled back)
  int threads = 0;               ///< OpenMP team the step ran on (its own choice or the caller's)
  /// Wall time of this step's assembly and solve (factorization included); the callers add
  /// the stages around it (boundary condition, SED).
  StageTimes stage_ms;
};

}  // namespace sedbridge::fem
