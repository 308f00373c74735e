#include "lcm/contact_estimate_message.h"

namespace sedbridge::lcm_io {

lcmt_contact_estimate ToLcm(const contact::ContactReport& report) {
  const contact::ContactEstimate& e = report.estimate;
  const sensors::ContactPrimitive& p = e.primitive;
  lcmt_contact_estimate m{};
  m.utime = report.scan_utime;
  m.source_scan_utime = report.scan_utime;
  m.shape = !e.contact                                    ? 0
            : e.two_contacts                              ? 4
            : p.shape == sensors::ContactShape::kSphere   ? 1
            : p.shape == sensors::ContactShape::kCylinder ? 2
            : p.shape == sensors::ContactShape::kPunch    ? 5
            : p.shape == sensors::ContactShape::kRoundPunch ? 6
            : p.shape == sensors::ContactShape::kCorner ? 7
                                                          : 3;
  m.x_mm = static_cast<float>(p.x_mm);
  m.y_mm = static_cast<float>(p.y_mm);
  m.radius_mm = static_cast<float>(p.radius_mm);
  m.yaw_deg = static_cast<float>(p.yaw_deg);
  m.length_mm = static_cast<float>(p.shape == sensors::ContactShape::kPunch ? 2 * p.half_size_mm[0] : p.length_mm);
  m.width_mm = p.shape == sensors::ContactShape::kPunch ? static_cast<float>(2 * p.half_size_mm[1]) : 0.0f;
  m.normal_force_N = static_cast<float>(p.normal_force_N);
  m.shear_x_N = static_cast<float>(p.shear_x_N);
  m.shear_y_N = static_cast<float>(p.shear_y_N);
  if (e.two_contacts) {
    const sensors::ContactPrimitive& q = e.second;
    m.x2_mm = static_cast<float>(q.x_mm);
    m.y2_mm = static_cast<float>(q.y_mm);
    m.radius2_mm = static_cast<float>(q.radius_mm);
    m.normal_force2_N = static_cast<float>(q.normal_force_N);
  }
  m.residual_rms_sigma = static_cast<float>(e.rms_sigma);
  m.fallback = report.fallback ? 1 : 0;
  m.indentation_mm = static_cast<float>(report.indentation_mm);
  m.num_taxels = static_cast<int32_t>(e.taxel_use.size());
  m.taxel_used.reserve(e.taxel_use.size());
  for (const contact::TaxelUse use : e.taxel_use) m.taxel_used.push_back(static_cast<int8_t>(use));
  m.num_taxels_used = e.taxels_used;
  m.model_inadequate = e.model_inadequate ? 1 : 0;
  return m;
}

}  // namespace sedbridge::lcm_io
