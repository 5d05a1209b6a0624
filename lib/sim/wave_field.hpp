// Smooth pseudo-random relief as a sum of plane waves: deterministic from a seed, C-infinity, cheap to evaluate
// anywhere, and the same value for every piece of geometry that touches the same point (so neighbouring
// primitives stay watertight). Used for floor unevenness, the roadway grade and wall/roof relief.
#pragma once

#include "sim/rng.hpp"

#include <vector>

namespace adit::sim {

class WaveField {
 public:
  WaveField() = default;  // zero everywhere
  // `count` waves with wavelengths log-uniform in [min_wavelength, max_wavelength] (m), amplitude growing with
  // wavelength (rough surfaces have more relief at long wavelengths), random directions (horizontal if
  // `planar`) and phases; scaled so the field's RMS is `rms` (m).
  WaveField(Rng& rng, int count, double min_wavelength, double max_wavelength, double rms, bool planar);

  double value(double x, double y, double z = 0.0) const;
  double rms() const { return rms_; }

 private:
  struct Wave {
    double kx, ky, kz, phase, amplitude;
  };
  std::vector<Wave> waves_;
  double rms_ = 0.0;
};

}  // namespace adit::sim
