#pragma once
// The thresholds of taxel health (sensors/taxel_health.h), key `taxel_health` of a sensor
// profile; units and ranges in config/sensors/README.md. The defaults leave the shipped
// healthy logs unchanged (no taxel masked, none re-tared).

#include "common/name_value.h"

namespace sedbridge::sensors {

struct TaxelHealthThresholds {
  bool enabled = true;
  /// Single-scan noise of one raw reading, 1 sigma [counts]: the unit of every margin below.
  double noise_counts = 2;
  /// Frozen: all of a taxel's raw readings bit-identical this long while most of the
  /// sensor's taxels show noise [s] (0 = off). 3-axis noise of 2 counts repeats one scan in
  /// ~300; 0.3 s at 100 Hz is 30 repeats running.
  double frozen_after_s = 0.3;
  /// Stuck high: the other taxels (less the largest of them) read less than this fraction of
  /// the least the forward model spreads from any load on the pad to them ...
  double isolated_fraction = 0.5;
  /// ... and by more than this many sigma of their summed noise, while the taxel reads more
  /// than this many sigma.
  double isolated_margin_sigma = 5;
  /// Dead: the taxel reads less than this fraction of the least its loaded nearest ring
  /// implies through the forward model ...
  double dead_fraction = 0.25;
  /// ... that least being above this many sigma of the taxel's noise.
  double dead_margin_sigma = 8;
  /// Stuck high this long running -> masked [s]; before that the taxel is left out of each
  /// scan it is suspect in (one loaded taxel with quiet neighbours is never a contact).
  double stuck_after_s = 0.03;
  /// Dead this long running -> masked [s].
  double dead_after_s = 0.05;
  /// A masked taxel behaves this long running -> unmasked [s] (stuck high: reads within
  /// noise; dead: reads what its ring implies; frozen: shows noise again).
  double recover_after_s = 0.2;
  /// Drift: while the sensor is quiet, a taxel's normal baseline is averaged over this
  /// time constant [s] (0 = off) ...
  double drift_tau_s = 2;
  /// ... and re-tared (its offset taken off every later reading) once it moved more than
  /// this many sigma ...
  double drift_retare_sigma = 10;
  /// ... if it moved less than this many sigma (more is a stuck taxel, not a creep).
  double drift_max_sigma = 100;

  template <typename Archive>
  void Serialize(Archive* a) {
    using config::Field;
    a->Visit(Field("enabled", &enabled));
    a->Visit(Field("noise_counts", &noise_counts).Unit("counts").Within({0, 1e6, true, false}));
    a->Visit(Field("frozen_after_s", &frozen_after_s).Unit("s").InRange(0.0, 60.0));
    a->Visit(Field("isolated_fraction", &isolated_fraction).InRange(0.01, 1.0));
    a->Visit(Field("isolated_margin_sigma", &isolated_margin_sigma).InRange(0.0, 1000.0));
    a->Visit(Field("dead_fraction", &dead_fraction).InRange(0.01, 1.0));
    a->Visit(Field("dead_margin_sigma", &dead_margin_sigma).InRange(0.0, 1000.0));
    a->Visit(Field("stuck_after_s", &stuck_after_s).Unit("s").InRange(0.0, 60.0));
    a->Visit(Field("dead_after_s", &dead_after_s).Unit("s").InRange(0.0, 60.0));
    a->Visit(Field("recover_after_s", &recover_after_s).Unit("s").InRange(0.0, 600.0));
    a->Visit(Field("drift_tau_s", &drift_tau_s).Unit("s").InRange(0.0, 3600.0));
    a->Visit(Field("drift_retare_sigma", &drift_retare_sigma).InRange(1.0, 1e6));
    a->Visit(Field("drift_max_sigma", &drift_max_sigma).InRange(1.0, 1e6));
  }
};

}  // namespace sedbridge::sensors
