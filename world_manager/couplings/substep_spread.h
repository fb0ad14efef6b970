// SPDX-License-Identifier: Apache-2.0
#pragma once
// Spreading one impulse over a world step's substep slots with a given centroid (local coupling, local_coupling.h).
//
// Slots 0 … m − 1 stand for impulses at times 0, h, …, (m − 1)·h of the step (a force held in substep k acts on the
// end state like an impulse at k·h). A weight per slot, w_k ≥ 0, Σ w_k = 1 and Σ k·w_k = c (c in slots, 0 ≤ c ≤ m − 1):
// momentum and the free body's displacement at the end of the step are those of the whole impulse at c. Among such
// weights, spread ones let contact friction meet the push as the force it was: a steady push over the window has its
// centroid mid-window, and concentrated at that one substep it would exceed that substep's friction budget μ·N·h
// n times over (a resting object would creep under a push friction holds).
//
// The weights are a linear ramp, w_k = 1/L + b·(k − k̄), on the first L slots (c below the middle) or the last L slots
// (c above it), k̄ the range's middle: the whole range (L = m) when |c − k̄| ≤ (m + 1)/6, where the ramp stays
// non-negative; otherwise the widest range that can still have centroid c, L = ⌊3·c + 2⌋ measured from the near end
// (a ramp on L slots reaches its lowest centroid, (L − 2)/3, when its far end touches zero). Uniform for c at the
// middle; all in slot 0 for c = 0.

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace impetus {

// How many slots the spread of an impulse with `centroid` covers: the widest a non-negative ramp with that centroid
// can be. `slot_count` ≥ 1, `centroid` clamped to [0, slot_count − 1].
inline int spread_length(double centroid, int slot_count) {
  const double last = static_cast<double>(slot_count - 1);
  const double c = std::clamp(centroid, 0.0, last);
  const double near = std::min(c, last - c);
  return std::min(slot_count, static_cast<int>(std::floor(3.0 * near + 2.0)));
}

// Calls add(slot, weight) for each slot of the spread; `slot_count` ≥ 1, `centroid` clamped to [0, slot_count − 1].
template <typename Add>
void spread_over_slots(double centroid, int slot_count, Add&& add) {
  const double last = static_cast<double>(slot_count - 1);
  const double c = std::clamp(centroid, 0.0, last);
  const bool from_end = c > 0.5 * last;  // mirror: measure from the end the centroid is nearer
  const double near = from_end ? last - c : c;
  const int length = spread_length(c, slot_count);
  if (length <= 1) {
    add(from_end ? slot_count - 1 : 0, 1.0);
    return;
  }
  const double L = static_cast<double>(length);
  const double middle = 0.5 * (L - 1.0);
  const double sum_of_squares = L * (L * L - 1.0) / 12.0;  // Σ (k − k̄)² over the range
  const double slope = (near - middle) / sum_of_squares;
  for (int k = 0; k < length; ++k) {
    const double weight = std::max(0.0, 1.0 / L + slope * (static_cast<double>(k) - middle));
    add(from_end ? slot_count - 1 - k : k, weight);
  }
}

}  // namespace impetus
