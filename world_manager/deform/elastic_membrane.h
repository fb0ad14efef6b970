// SPDX-License-Identifier: Apache-2.0
#pragma once
// The elastic law of a deformable slab (deformable_material.h; docs/deformation.md): a membrane on an elastic
// foundation over the top face's grid of cells, each cell's depth d (m, into the slab; negative: bulging out) moving by
//     μ·d̈ = −k·d + τ·∇²d − c·ḋ + f/A
// with the five-point Laplacian over the grid and free edges (a cell at the edge has no neighbour beyond it), f the
// force on the cell (N), A its area. The slab's unyielding floor (deformable_surface.h room_m) stops a cell that
// reaches it: its speed into the floor is lost and counted.
//
// Integration, in substeps h ≤ 1/(2·ω_max) (DeformableMaterial::highest_frequency_radps): each cell's own terms (the
// foundation and the damping) by the trapezoid rule, the skin's from the substep's start, so every cell solves in
// place (elastic_membrane.cpp has the update). Energy books: the work of the forces Σ f·Δd, the damping's loss
// Σ c·A·u·Δd (u the substep's mean speed), the floor's ½·μ·A·v², and what the surface holds, E = ½·vᵀ·M·v +
// ½·dᵀ·K·d (K the foundation's k·A per cell and the skin's τ·A/Δ² per pair of neighbours). One substep changes E by
// exactly
//     ΔE = Σ f·Δd − Σ c·A·u·Δd + ½·Δdᵀ·K_τ·Δd
// the last term S ≥ 0 the scheme's own share, the skin's lag over the substep (K_τ its part of K). Evaluated at the
// substep's start the foundation would lag too and act as a negative damping k·h/2 (8 % of the default gel's
// damping at its substeps; a press and release netted +1 % of its work), energy no hand put in. S, a passivity
// observer gives back, as a time-domain passivity controller does at a port: the speeds are scaled by √(1 − S/K) at
// the next substep's start, K the kinetic energy (S is of order (h·ω)²·K; what K cannot give at once waits for the
// next substep). The books balance exactly, work + scheme = damped + stopped + E, scheme ≤ 0 between substeps
// (but for such a wait), except in a cell the floor stopped.
//
// The static response: the depth a steady force of 1 N spread over the contact pad (the paraboloid of
// deformable_material.h) makes about it, (k − τ·∇²)·d = p, solved once at construction on a window about one cell
// (Eigen's sparse Cholesky). Its value under the pad's centre is the pad's compliance: what the haptic side yields the
// surface by under the finger between frames (haptic_controller/local_yield.h).
//
// Not thread-safe; owned by a DeformableSurface. step() does not allocate.

#include "world_manager/deform/deformable_material.h"

#include <cstddef>
#include <vector>

namespace impetus {

class ElasticMembrane {
 public:
  // A grid of `columns` × `rows` cells `cell_x_m` × `cell_y_m`, at rest, whose cells stop at `max_depth_m`.
  ElasticMembrane(const DeformableMaterial& material, std::size_t columns, std::size_t rows, double cell_x_m,
                  double cell_y_m, double max_depth_m);

  // Moves `depth_m` (per cell, row-major, the owner's) over `period_s` under `force_N` per cell, held constant over
  // the period; cells with a finite `pin_m` (if given) are set to that depth at once and held there, still (their
  // work is counted as the energy that changed). Returns whether any cell moved.
  bool step(double period_s, const std::vector<double>& force_N, std::vector<double>& depth_m,
            const std::vector<double>* pin_m = nullptr);
  // The substeps a period of `period_s` takes: kSubstepsPerRadian per radian of the fastest mode. The skin's lag
  // the observer gives back, measured for a 1 N press and release on the default gel: 25 % of the work at one
  // substep a radian, 4.3 % at two, 1.7 % at four (explicit symplectic schemes are stable to two radians a step).
  static constexpr double kSubstepsPerRadian = 2.0;
  std::size_t substeps(double period_s) const;

  double work_J() const { return work_J_; }              // done on the surface by the forces so far
  double damped_J() const { return damped_J_; }          // lost to damping so far
  double stopped_J() const { return stopped_J_; }        // lost where the floor stopped a cell
  double scheme_J() const { return scheme_J_; }          // the integrator's net share (≤ 0; above)
  double given_back_J() const { return projected_J_; }  // what the observer took back (≥ 0)
  double stored_J(const std::vector<double>& depth_m) const;  // what the surface holds now
  bool at_rest() const { return at_rest_; }

  // The static response to 1 N over the pad centred on a cell's centre, at offset (dx, dy) from that centre (m/N;
  // bilinear between cells, zero beyond the window it was solved on).
  double static_response_mpN(double dx_m, double dy_m) const;
  double compliance_mpN() const { return static_response_mpN(0.0, 0.0); }
  // The window's half width in cells, each way (the response beyond is below 10⁻⁶ of its peak, or the slab ends).
  std::size_t response_half_cells() const { return response_half_; }

 private:
  void solve_static_response();

  DeformableMaterial material_;
  std::size_t columns_ = 0;
  std::size_t rows_ = 0;
  double cell_x_m_ = 0.0;
  double cell_y_m_ = 0.0;
  double max_depth_m_ = 0.0;
  std::vector<double> velocity_mps_;  // per cell, ḋ
  std::vector<double> moved_m_;       // per cell, scratch: the substep's Δd
  bool at_rest_ = true;               // every depth and speed exactly zero
  double work_J_ = 0.0;
  double damped_J_ = 0.0;
  double stopped_J_ = 0.0;
  double scheme_J_ = 0.0;
  double projected_J_ = 0.0;
  std::size_t response_half_ = 0;
  std::vector<double> response_mpN_;  // (2·half + 1)² cells, row-major, the pad's centre at the middle
};

}  // namespace impetus
