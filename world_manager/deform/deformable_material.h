// SPDX-License-Identifier: Apache-2.0
#pragma once
// A deformable slab's material (paper §6.4; docs/deformation.md): what a scene's "deformable" block gives
// (docs/scene-format.md), in SI units, with the ranges the scene parser enforces. Two laws share the grid, the pad and
// the two rules:
//
// Plastic (clay-like; Bingham, as an indenter sinks into a plastic: the material under the pad flows once the mean
// pressure under it exceeds the yield stress, at a speed set by the excess):
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
//
// Elastic (a gel or rubber pad: a membrane on an elastic foundation, elastic_membrane.h): each cell's depth d moves by
//     μ·d̈ = −k·d + τ·∇²d − c·ḋ + f/A
// μ the areal density, k the foundation's stiffness (pressure per metre of depth: Young's modulus over thickness),
// τ the skin's tension, c the damping, f the push the cell receives, as a force spread over the world period after
// the one it was given in (its whole momentum, a period late). Nothing stays: the surface springs back.
#include <cstdint>

namespace impetus {

struct DeformableMaterial {
  enum class Law : std::uint32_t { plastic = 0, elastic = 1 };
  Law law = Law::plastic;
  // What moves the slab (docs/deformation.md "two rules"):
  //   impulse:     the push the haptic side integrated, where it was given (paper §6.4's proposal);
  //   penetration: the finger's penetration sampled at each world step (the previous method): plastic, the surface
  //                moved in by plasticity × it (H3D's coordinate deformer); elastic, the force of the contact's spring
  //                at that penetration, held over the period (a world that samples the contact, paper Fig. 1).
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
  // Elastic only. A soft silicone gel pad 2 cm thick (Young's modulus ~50 kPa, E/thickness = 2.5 MPa/m): a 1 N
  // press sinks the pad's centre about 5 mm, as a fingertip sinks into a gel wrist rest.
  double stiffness_Papm = 2.5e6;
  // The skin's tension (N/m): a thin stretched silicone skin; it spreads a press over √(τ/k) ≈ 2 mm beyond the pad.
  double tension_Npm = 10.0;
  // Mass per area of the moving layer (kg/m²): 2 cm of gel at 1000 kg/m³.
  double areal_density_kgpm2 = 20.0;
  // Pa·s/m: about 0.3 of the foundation's critical damping 2·√(k·μ) (soft gels lose ~half an oscillation's energy).
  double damping_Paspm = 4000.0;
  // The slab's last tenth does not yield: it is pressed against whatever holds the slab, so no press makes a hole.
  static constexpr double kUnyieldingFraction = 0.1;

  // The push the surface holds without yielding, F_y = σ_y·π·a² (N), and how far the pad's centre goes in per N·s of
  // push beyond it, 2/(π·a²·η) (m/(N·s)). Zero under the penetration rule, which the push does not dent, and for the
  // elastic law, which every push moves and none dents.
  double yield_force_N() const;
  double yield_depth_mpNs() const;
  // Elastic only: the highest angular frequency a grid of cells `cell_x_m` × `cell_y_m` carries,
  // ω² = (k + τ·(4/Δx² + 4/Δy²))/μ (rad/s): the integrator's substeps stay below 1/(2·ω) (elastic_membrane.h).
  double highest_frequency_radps(double cell_x_m, double cell_y_m) const;
};

const char* to_string(DeformableMaterial::Rule rule);
const char* to_string(DeformableMaterial::Law law);

}  // namespace impetus
