#pragma once
// Isotropic linear elastic material (paper Table II), SI units.

#include <string>

namespace sedbridge::fem {

struct LinearElasticMaterial {
  std::string name;               ///< tissue name, e.g. "epidermis"
  double youngs_modulus_Pa = 0;   ///< E
  double poisson_ratio = 0;       ///< nu, in (-1, 0.5)
  double density_kg_m3 = 0;       ///< rho

  double lame_mu_Pa() const { return youngs_modulus_Pa / (2.0 * (1.0 + poisson_ratio)); }
  double lame_lambda_Pa() const {
    return youngs_modulus_Pa * poisson_ratio /
           ((1.0 + poisson_ratio) * (1.0 - 2.0 * poisson_ratio));
  }
};

}  // namespace sedbridge::fem
