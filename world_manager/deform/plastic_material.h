// SPDX-License-Identifier: Apache-2.0
#pragma once
// A plastic (clay-like) material for a deformable slab (paper §6.4; docs/deformation.md): what a scene's
// "deformable" block gives (docs/scene-format.md), in SI units, with the ranges the scene parser enforces.
//
// The law (Bingham-like, as an indenter sinks into a plastic: the material under the pad flows once the mean pressure
// under it exceeds the yield stress, at a speed set by the excess):
//     push beyond yield, per haptic tick k:   e_k = max(0, p_k − F_y·Δt),   F_y = σ_y·π·a²
//     dent of cell c:                         Δdepth_c = Σ_k e_k·w_c(x_k) / (A·η)
// p_k the push into the surface in tick k (N·s), a the contact pad's radius, σ_y the yield stress, η the flow
// resistance, A a cell's area, w_c(x) the pad's pressure shape about the contact x_k (a paraboloid, normalised over
// the cells: Σ_c w_c = 1). The threshold is taken at the haptic rate, where the push is known tick by tick (the
// haptic side's impulse accumulator); the world receives Σ e_k with where and when (press_path.h) and dents linearly,
// so what a period's boundary cuts does not change the dent. A push below F_y leaves no mark however long it lasts.
// The dent's volume is Σ e_k / η: the law's own check. Under the pad's centre the surface goes in by
// e·w(0)/(A·η) ≈ 2·e/(π·a²·η) (the paraboloid's peak is twice its mean), what the haptic side yields it by between
// world frames (haptic_controller/local_yield.h).

#include <cstdint>

namespace impetus {

struct PlasticMaterial {
  // What dents the slab (docs/deformation.md "two rules"):
  //   impulse:     the push the haptic side integrated, where it was given (paper §6.4's proposal);
  //   penetration: the finger's penetration sampled at each world step, the surface moved by plasticity × it
  //                (the previous method: H3D's coordinate deformer).
  enum class Rule : std::uint32_t { impulse = 0, penetration = 1 };
  Rule rule = Rule::impulse;
  // Soft modelling clay and wet potter's clay start to flow at a few kPa (snow a little above): a fingertip's
  // contact patch (below) starts to dent 5 kPa at about 0.6 N, a light press.
  double yield_stress_Pa = 5e3;
  // The excess pressure that drives the surface in at 1 m/s (Pa·s/m): 10^6 has a 10 kPa excess (a 1.7 N press)
  // dent at 1 cm/s, as a finger sinks slowly into clay.
  double flow_resistance_Paspm = 1e6;
  // The finger is a point; the push is spread over its pad, a paraboloid of pressure of this radius (a fingertip's
  // contact patch at about 1 N is about 1 cm², radius ~6 mm), so the dent does not depend on the grid's cells.
  double contact_radius_m = 6e-3;
  // The grid's cell edge on the top face; at most half the contact radius, so the pad spans cells.
  double cell_m = 1e-3;
  // Penetration rule only: the fraction of the sampled penetration the surface follows at each world step (H3D's
  // plasticity), in (0, 1].
  double plasticity = 1.0;
  // The slab's last tenth does not yield: it is pressed against whatever holds the slab, so no press makes a hole.
  static constexpr double kUnyieldingFraction = 0.1;

  // The push the surface holds without yielding, F_y = σ_y·π·a² (N), and how far the pad's centre goes in per N·s of
  // push beyond it, 2/(π·a²·η) (m/(N·s)). Zero under the penetration rule, which the push does not dent.
  double yield_force_N() const;
  double yield_depth_mpNs() const;
};

const char* to_string(PlasticMaterial::Rule rule);

}  // namespace impetus
