#pragma once
// contact::ContactReport -> lcmt_contact_estimate (channel CONTACT_ESTIMATE).

#include "contact/contact_estimate.h"
#include "sedbridge/lcmt_contact_estimate.hpp"

namespace sedbridge::lcm_io {

/// utime and source_scan_utime: the scan's (a publisher sets utime to the send time). shape:
/// 0 no contact, 1 sphere, 2 cylinder, 3 flat, 4 two spheres (x2..normal_force2 then the
/// second's; 0 otherwise). Values are narrowed to float as they are. taxel_used: the
/// estimate's taxel_use (contact::TaxelUse values), num_taxels_used its taxels_used.
lcmt_contact_estimate ToLcm(const contact::ContactReport& report);

}  // namespace sedbridge::lcm_io
