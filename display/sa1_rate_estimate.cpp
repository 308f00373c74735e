#include "display/sa1_rate_estimate.h"

#include <cmath>
#include <stdexcept>

namespace sedbridge::display {
namespace {

void Check(const Sa1RateParams& p) {
  auto positive = [](double x) { return std::isfinite(x) && x > 0; };
  if (!positive(p.max_rate_Hz) || !positive(p.half_rate_sed_Pa) || !positive(p.hill_exponent) ||
      !std::isfinite(p.threshold_Pa) || p.threshold_Pa < 0)
    throw std::invalid_argument("Sa1RateParams: parameters must be finite and positive");
}

}  // namespace

double EstimateSa1Rate(double sed_Pa, const Sa1RateParams& p) {
  Check(p);
  if (std::isnan(sed_Pa)) return sed_Pa;
  const double s = sed_Pa - p.threshold_Pa;
  if (!(s > 0)) return 0;
  if (std::isinf(s)) return p.max_rate_Hz;
  // Written as 1 / (1 + (h/s)^n) so huge s neither overflows nor loses the limit.
  return p.max_rate_Hz / (1.0 + std::pow(p.half_rate_sed_Pa / s, p.hill_exponent));
}

std::vector<double> EstimateSa1Rates(const std::vector<double>& sed_Pa, const Sa1RateParams& p) {
  std::vector<double> out;
  out.reserve(sed_Pa.size());
  for (double s : sed_Pa) out.push_back(EstimateSa1Rate(s, p));
  return out;
}

}  // namespace sedbridge::display
