// Robust losses of a residual block as iteratively reweighted least squares: a block with squared norm s
// costs rho(s) / 2 and enters the normal equations with weight rho'(s). These are Ceres's HuberLoss and
// CauchyLoss (rho'' <= 0 for both, so Ceres's Triggs correction reduces to the same weight): switching the
// solver from Ceres to this one keeps the problem that is minimised.
#pragma once

#include <cmath>
#include <string>

namespace adit {

enum class RobustLoss { kNone, kHuber, kCauchy };

// "huber", "cauchy" or "none" (anything else is Huber, the default).
inline RobustLoss robustLossFromName(const std::string& name) {
  if (name == "none") return RobustLoss::kNone;
  if (name == "cauchy") return RobustLoss::kCauchy;
  return RobustLoss::kHuber;
}

struct RobustKernel {
  RobustLoss loss = RobustLoss::kHuber;
  double scale = 0.1;  // metres of residual

  // rho'(s) for a block of squared norm s.
  double weight(double s) const {
    const double a2 = scale * scale;
    switch (loss) {
      case RobustLoss::kHuber: return s <= a2 ? 1.0 : scale / std::sqrt(s);
      case RobustLoss::kCauchy: return 1.0 / (1.0 + s / a2);
      case RobustLoss::kNone: break;
    }
    return 1.0;
  }
  // rho(s).
  double cost(double s) const {
    const double a2 = scale * scale;
    switch (loss) {
      case RobustLoss::kHuber: return s <= a2 ? s : 2.0 * scale * std::sqrt(s) - a2;
      case RobustLoss::kCauchy: return a2 * std::log1p(s / a2);
      case RobustLoss::kNone: break;
    }
    return s;
  }
};

}  // namespace adit
