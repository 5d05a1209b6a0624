#include "sim/wave_field.hpp"

#include <cmath>

namespace adit::sim {

WaveField::WaveField(Rng& rng, int count, double min_wavelength, double max_wavelength, double rms, bool planar)
    : rms_(rms) {
  if (count <= 0 || rms <= 0.0 || min_wavelength <= 0.0 || max_wavelength < min_wavelength) return;
  constexpr double kTwoPi = 6.283185307179586;
  double variance = 0.0;
  for (int i = 0; i < count; ++i) {
    const double wavelength = min_wavelength * std::pow(max_wavelength / min_wavelength, rng.uniform());
    const double azimuth = rng.uniform(0.0, kTwoPi);
    const double elevation = planar ? 0.0 : std::asin(rng.uniform(-1.0, 1.0));
    const double k = kTwoPi / wavelength;
    Wave w;
    w.kx = k * std::cos(elevation) * std::cos(azimuth);
    w.ky = k * std::cos(elevation) * std::sin(azimuth);
    w.kz = k * std::sin(elevation);
    w.phase = rng.uniform(0.0, kTwoPi);
    w.amplitude = std::sqrt(wavelength);  // relief spectrum: amplitude ~ sqrt(wavelength)
    variance += 0.5 * w.amplitude * w.amplitude;
    waves_.push_back(w);
  }
  const double scale = rms / std::sqrt(variance);
  for (Wave& w : waves_) w.amplitude *= scale;
}

double WaveField::value(double x, double y, double z) const {
  double sum = 0.0;
  for (const Wave& w : waves_) sum += w.amplitude * std::sin(w.kx * x + w.ky * y + w.kz * z + w.phase);
  return sum;
}

}  // namespace adit::sim
