// SPDX-License-Identifier: MIT
// Drift tracking for quantities a simulation should conserve (energy, momentum, constraints).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace hamel::runtime {

/// Records the largest deviation of a conserved quantity from its initial value.
///
/// A NaN value makes both deviations NaN for good: a broken state must not be
/// hidden by later, well-behaved samples.
class DriftMonitor {
 public:
  /// Starts monitoring a quantity whose exact value is `initial`.
  explicit DriftMonitor(double initial) : initial_(initial) {}

  /// Takes one more sample of the quantity.
  void update(double value) {
    const double deviation = std::fabs(value - initial_);
    // Once max_abs_ is NaN no comparison succeeds any more, which keeps it NaN.
    if (std::isnan(deviation) || deviation > max_abs_) {
      max_abs_ = deviation;
    }
  }

  /// The value given at construction.
  double initial() const { return initial_; }

  /// max |value - initial| over all samples so far (0 before the first sample).
  double max_abs_deviation() const { return max_abs_; }

  /// max_abs_deviation() / max(|initial|, tiny), tiny being the smallest normal
  /// double. The floor only avoids 0/0: a quantity that starts at exactly zero
  /// has no scale, and rather than invent one (which would quietly turn this
  /// into an absolute measure) the result becomes huge or infinite as soon as
  /// anything drifts, so that a relative threshold fails loudly. Use
  /// max_abs_deviation() for such quantities.
  double max_relative_deviation() const {
    return max_abs_ / std::max(std::fabs(initial_), std::numeric_limits<double>::min());
  }

 private:
  double initial_;
  double max_abs_ = 0.0;
};

}  // namespace hamel::runtime
