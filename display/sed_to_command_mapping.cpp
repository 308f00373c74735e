#include "display/sed_to_command_mapping.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sedbridge::display {
namespace {

// Smallest squared vertex-site distance in the Shepard weights [mm^2] (1 µm squared): a
// vertex on the site gets a weight that dominates instead of an infinite one.
constexpr double kMinShepardDistanceSq_mm2 = 1e-6;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void Require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("SedToCommandMapping: " + what);
}

}  // namespace

SedToCommandMapping::SedToCommandMapping(std::vector<double> site_x_mm,
                                         std::vector<double> site_y_mm, MappingParams params)
    : site_x_mm_(std::move(site_x_mm)), site_y_mm_(std::move(site_y_mm)), params_(std::move(params)) {
  const MappingParams& m = params_;
  Require(site_x_mm_.size() == site_y_mm_.size(), "site x and y lengths differ");
  for (std::size_t i = 0; i < size(); ++i)
    Require(std::isfinite(site_x_mm_[i]) && std::isfinite(site_y_mm_[i]), "non-finite site");
  Require(std::isfinite(m.radius_mm) && m.radius_mm > 0, "radius_mm must be > 0");
  Require(!(m.z_min_mm >= m.z_max_mm) && !std::isnan(m.z_min_mm) && !std::isnan(m.z_max_mm),
          "z window must have min < max");
  Require(std::isfinite(m.threshold_Pa) && m.threshold_Pa >= 0, "threshold_Pa must be >= 0");
  Require(std::isfinite(m.reference_Pa) && m.reference_Pa > 0, "reference_Pa must be > 0");
  Require(std::isfinite(m.gain) && m.gain > 0, "gain must be > 0");
  Require(std::isfinite(m.exponent) && m.exponent > 0, "exponent must be > 0");
  Require(std::isfinite(m.saturation) && m.saturation > 0, "saturation must be > 0");
  Require(m.calibration_gain.empty() || m.calibration_gain.size() == size(),
          "calibration gain length != actuator count");
  Require(m.calibration_offset.empty() || m.calibration_offset.size() == size(),
          "calibration offset length != actuator count");
  for (double g : m.calibration_gain) Require(std::isfinite(g) && g > 0, "calibration gain <= 0");
  for (double o : m.calibration_offset) Require(std::isfinite(o), "non-finite calibration offset");
}

SedToCommandMapping::SedToCommandMapping(const DisplayProfile& profile)
    : SedToCommandMapping(profile.x_mm, profile.y_mm, profile.mapping) {}

double SedToCommandMapping::Sample(const SedField& field, std::size_t site) const {
  const std::size_t n = field.sed_Pa.size();
  const bool has_z = !field.z_mm.empty();
  if (field.x_mm.size() != n || field.y_mm.size() != n || (has_z && field.z_mm.size() != n))
    return kNaN;
  const double sx = site_x_mm_[site], sy = site_y_mm_[site];
  const double r2 = params_.radius_mm * params_.radius_mm;
  bool bad = false;
  double max_s = 0, sum = 0, wsum = 0;
  std::size_t count = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const double dx = field.x_mm[v] - sx, dy = field.y_mm[v] - sy;
    const double d2 = dx * dx + dy * dy;
    // NaN coordinates fail this comparison and are skipped.
    if (!(d2 <= r2)) continue;
    if (has_z && !(field.z_mm[v] >= params_.z_min_mm && field.z_mm[v] <= params_.z_max_mm))
      continue;
    double s = field.sed_Pa[v];
    if (!std::isfinite(s)) {
      bad = true;
      break;
    }
    s = std::max(s, 0.0);
    ++count;
    switch (params_.sampling) {
      case SamplingMethod::kMaxWithinRadius: max_s = std::max(max_s, s); break;
      case SamplingMethod::kMeanWithinRadius: sum += s; break;
      case SamplingMethod::kInterpolate: {
        const double w = 1.0 / std::max(d2, kMinShepardDistanceSq_mm2);  // Shepard weights 1/d^2
        sum += w * s;
        wsum += w;
        break;
      }
    }
  }
  if (bad) return kNaN;
  if (count == 0) return 0;
  switch (params_.sampling) {
    case SamplingMethod::kMaxWithinRadius: return max_s;
    case SamplingMethod::kMeanWithinRadius: {
      const double mean = sum / count;
      // sum of huge finite values overflows to Inf; that is "very large", not a fault.
      return std::isfinite(mean) ? mean : std::numeric_limits<double>::max();
    }
    case SamplingMethod::kInterpolate: {
      const double s = sum / wsum;
      return std::isfinite(s) ? s : std::numeric_limits<double>::max();
    }
  }
  return kNaN;
}

bool SedToCommandMapping::Reads(double x_mm, double y_mm, double z_mm) const {
  if (!(z_mm >= params_.z_min_mm && z_mm <= params_.z_max_mm)) return false;
  const double r2 = params_.radius_mm * params_.radius_mm;
  for (std::size_t i = 0; i < size(); ++i) {
    const double dx = x_mm - site_x_mm_[i], dy = y_mm - site_y_mm_[i];
    if (dx * dx + dy * dy <= r2) return true;  // the same test as Sample's
  }
  return false;
}

double SedToCommandMapping::Transfer(double sed_Pa, std::size_t site) const {
  if (std::isnan(sed_Pa)) return kNaN;
  const MappingParams& m = params_;
  const double x = sed_Pa - m.threshold_Pa;  // +Inf stays +Inf and saturates below
  if (!(x > 0)) return 0;
  double y = m.gain * std::pow(x / m.reference_Pa, m.exponent);
  if (!(y <= m.saturation)) y = m.saturation;
  if (!m.calibration_gain.empty()) y *= m.calibration_gain[site];
  if (!m.calibration_offset.empty()) y += m.calibration_offset[site];
  return y;
}

SedToCommandMapping::Result SedToCommandMapping::Map(const SedField& field) const {
  Result r;
  r.check = CheckSedField(field);
  r.sed_at_site_Pa.resize(size());
  r.requested.resize(size());
  // A NaN/Inf anywhere (or mismatched lengths) means the FE step went wrong: its finite
  // values are not trustworthy either, so the whole field is rejected, not just nearby sites.
  const bool reject = !r.check.consistent || r.check.non_finite_sed > 0 ||
                      r.check.non_finite_position > 0;
  for (std::size_t i = 0; i < size(); ++i) {
    r.sed_at_site_Pa[i] = reject ? kNaN : Sample(field, i);
    r.requested[i] = Transfer(r.sed_at_site_Pa[i], i);
  }
  return r;
}

}  // namespace sedbridge::display
