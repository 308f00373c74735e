#include "sensors/tactile_model_params.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/yaml_read_archive.h"

namespace sedbridge::sensors {

void CheckKernel(const RadialKernel& k, const char* name) {
  if (!std::isfinite(k.gain) || !(k.width_mm > 0) || !std::isfinite(k.width_mm) || !(k.power > 0) ||
      !std::isfinite(k.power))
    throw std::invalid_argument(std::string("forward model kernel '") + name +
                                "' needs a finite gain, width_mm > 0 and power > 0");
}

std::array<double, TactileModelParams::kCount> TactileModelParams::ToArray() const {
  return {contact_modulus_kPa, pad_size_mm,
          normal.gain, normal.width_mm, normal.power,
          spread.gain, spread.width_mm, spread.power,
          shear.gain, shear.width_mm, shear.power,
          shear_cross.gain, shear_cross.width_mm, shear_cross.power,
          shear_lift.gain, shear_lift.width_mm, shear_lift.power};
}

TactileModelParams TactileModelParams::FromArray(const std::array<double, kCount>& a, const TactileModelParams& fixed) {
  TactileModelParams p = fixed;
  p.contact_modulus_kPa = a[0];
  p.pad_size_mm = a[1];
  RadialKernel* k[5] = {&p.normal, &p.spread, &p.shear, &p.shear_cross, &p.shear_lift};
  for (int i = 0; i < 5; ++i) *k[i] = {a[2 + 3 * i], a[3 + 3 * i], a[4 + 3 * i]};
  return p;
}

const std::array<const char*, TactileModelParams::kCount>& TactileModelParams::Names() {
  static const std::array<const char*, kCount> names = {
      "contact_modulus_kPa", "pad_size_mm",      "normal.gain",      "normal.width_mm",
      "normal.power",        "spread.gain",      "spread.width_mm",  "spread.power",
      "shear.gain",          "shear.width_mm",   "shear.power",      "shear_cross.gain",
      "shear_cross.width_mm", "shear_cross.power", "shear_lift.gain", "shear_lift.width_mm",
      "shear_lift.power"};
  return names;
}

TactileModelParams ParseTactileModelParams(config::MapReader& reader) {
  TactileModelParams p;
  config::YamlReadArchive archive(&reader);
  p.Serialize(&archive);
  config::MapReader kernels = reader.Child("kernels");
  const std::pair<const char*, RadialKernel*> named[5] = {{"normal", &p.normal},
                                                           {"spread", &p.spread},
                                                           {"shear", &p.shear},
                                                           {"shear_cross", &p.shear_cross},
                                                           {"shear_lift", &p.shear_lift}};
  for (const auto& [name, kernel] : named) {
    const auto v = kernels.Required<std::vector<double>>(name);
    if (v.size() != 3) kernels.Fail(kernels.Node(name), std::string("'") + name + "' needs [gain, width_mm, power]");
    *kernel = {v[0], v[1], v[2]};
    try {
      CheckKernel(*kernel, name);
    } catch (const std::invalid_argument& e) {
      kernels.Fail(kernels.Node(name), e.what());
    }
  }
  kernels.Finish();
  return p;
}

std::string TactileModelParamsYaml(const TactileModelParams& p, int indent) {
  const std::string pad(indent, ' ');
  std::ostringstream s;
  s.precision(6);
  s << pad << "contact_modulus_kPa: " << p.contact_modulus_kPa << "\n"
    << pad << "pad_size_mm: " << p.pad_size_mm << "\n"
    << pad << "grid_mm: " << p.grid_mm << "\n";
  if (p.rod_min_halfwidth_mm > 0) s << pad << "rod_min_halfwidth_mm: " << p.rod_min_halfwidth_mm << "\n";
  s
    << pad << "kernels:                       # [gain, width_mm, power]\n";
  const std::pair<const char*, const RadialKernel*> named[5] = {{"normal", &p.normal},
                                                                 {"spread", &p.spread},
                                                                 {"shear", &p.shear},
                                                                 {"shear_cross", &p.shear_cross},
                                                                 {"shear_lift", &p.shear_lift}};
  for (const auto& [name, k] : named)
    s << pad << "  " << name << ": [" << k->gain << ", " << k->width_mm << ", " << k->power << "]\n";
  return s.str();
}

}  // namespace sedbridge::sensors
