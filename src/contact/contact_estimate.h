#pragma once
// What the contact stage says about one scan: the reconstructed contact (ContactEstimate),
// and what it reports for the scan (ContactReport: CONTACT_ESTIMATE on LCM, written by
// src/lcm/contact_estimate_message.h). Plain structs: any stage may hold them.

#include <cstdint>
#include <string>
#include <vector>

#include "sensors/contact_primitive.h"

namespace sedbridge::contact {

/// How the fit weighed a taxel (ContactEstimate::taxel_use; CONTACT_ESTIMATE taxel_used).
enum class TaxelUse : uint8_t {
  kLeftOut = 0,    ///< no weight: invalid, non-finite, or masked by taxel health
  kUsed = 1,       ///< all its channels weighed by their noise
  kSaturated = 2,  ///< only "at least full scale" on its normal axis
  kLoneMisfit = 3, ///< left out by the fit: it alone carried the misfit (ReconstructionOptions::lone_taxel_share)
};

/// What one scan says about the contact.
struct ContactEstimate {
  bool contact = false;       ///< something presses (force >= min_force_N)
  bool ok = false;            ///< contact and a trustworthy fit (else: fall back)
  /// Pad frame; normal_force_N = 0 when no contact. With two contacts: the first sphere, its
  /// own normal force, and the whole tangential force.
  sensors::ContactPrimitive primitive;
  bool two_contacts = false;  ///< a second sphere touches at the same time
  sensors::ContactPrimitive second;  ///< the second sphere (its normal force; no shear)
  double rms_sigma = 0;       ///< RMS residual in single-scan noise units (about 1 = within noise)
  int averaged_scans = 1;     ///< scans in the hold mean that was fitted (1: this scan alone)
  int evaluations = 0;        ///< forward-model evaluations this scan
  int evaluation_cost = 0;    ///< the same weighted by patch size, as the amortized budgets count them
  bool warm_started = false;  ///< the last scan's estimate was refined, no model selection
  std::string problem;        ///< why not ok
  /// Contact, and no model explains the scans within noise: the best fit's RMS residual (over
  /// the hold window, in single-scan noise) above what noise and the model's error leave
  /// (ReconstructionOptions::adequacy_z, model_error_sigma), or no plausible fit at all
  /// (every fallback). Said, never silent: the answer may be the
  /// wrong object even when ok (CONTACT_ESTIMATE model_inadequate).
  bool model_inadequate = false;
  /// Per taxel (sensor profile order), how the fit weighed it: TaxelUse. Empty when the scan
  /// did not reach the fit (wrong size).
  std::vector<TaxelUse> taxel_use;
  int taxels_used = 0;        ///< taxels TaxelUse::kUsed or kSaturated

  /// The whole pressing force [N] (both spheres of a pair).
  double normal_force_N() const {
    return primitive.normal_force_N + (two_contacts ? second.normal_force_N : 0.0);
  }
};

/// What the contact stage reports for one scan (CONTACT_ESTIMATE).
struct ContactReport {
  int64_t scan_utime = 0;      ///< the scan's time [us]
  ContactEstimate estimate;    ///< leader pad frame
  bool fallback = false;       ///< the pressure map answered the scan
  double indentation_mm = 0;   ///< the leader press's indentation (0 when not pressed)
};

}  // namespace sedbridge::contact
