// SPDX-License-Identifier: Apache-2.0
#include "world_manager/deform/elastic_membrane.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace impetus {

ElasticMembrane::ElasticMembrane(const DeformableMaterial& material, std::size_t columns, std::size_t rows,
                                 double cell_x_m, double cell_y_m, double max_depth_m)
    : material_(material),
      columns_(columns),
      rows_(rows),
      cell_x_m_(cell_x_m),
      cell_y_m_(cell_y_m),
      max_depth_m_(max_depth_m),
      velocity_mps_(columns * rows, 0.0),
      moved_m_(columns * rows, 0.0) {
  solve_static_response();
}

std::size_t ElasticMembrane::substeps(double period_s) const {
  const double omega_radps = material_.highest_frequency_radps(cell_x_m_, cell_y_m_);
  return static_cast<std::size_t>(std::max(1.0, std::ceil(kSubstepsPerRadian * period_s * omega_radps)));
}

bool ElasticMembrane::step(double period_s, const std::vector<double>& force_N, std::vector<double>& depth_m,
                           const std::vector<double>* pin_m) {
  const bool pinned = pin_m != nullptr;
  const bool pushed = pinned || std::any_of(force_N.begin(), force_N.end(), [](double f) { return f != 0.0; });
  if (at_rest_ && !pushed) return false;
  at_rest_ = false;
  if (pinned) {
    // The pins move their cells at once and stop them: their work is what that changed the surface's energy by.
    const double before_J = stored_J(depth_m);
    for (std::size_t i = 0; i < depth_m.size(); ++i) {
      if (std::isnan((*pin_m)[i])) continue;
      depth_m[i] = std::min((*pin_m)[i], max_depth_m_);
      velocity_mps_[i] = 0.0;
    }
    work_J_ += stored_J(depth_m) - before_J;
  }
  const std::size_t count = substeps(period_s);
  const double h_s = period_s / static_cast<double>(count);
  const double mu = material_.areal_density_kgpm2;
  const double area_m2 = cell_x_m_ * cell_y_m_;
  const double gx = material_.tension_Npm / (cell_x_m_ * cell_x_m_);  // Pa/m per neighbour along x
  const double gy = material_.tension_Npm / (cell_y_m_ * cell_y_m_);
  const double k = material_.stiffness_Papm;
  const double implicit = 0.25 * h_s * h_s * k + 0.5 * h_s * material_.damping_Paspm;
  const double keep = mu - implicit;
  const double inverse_diagonal = 1.0 / (mu + implicit);
  const double* d = depth_m.data();
  double* v = velocity_mps_.data();
  double* moved = moved_m_.data();
  const double cell_kg = mu * area_m2;
  double scale = 1.0;  // the speeds' factor the observer decided in the last substep (below)
  for (std::size_t s = 0; s < count; ++s) {
    // Each cell's own terms by the trapezoid rule, the skin's from the step's start (so each cell solves in place):
    //     μ·(v₁ − v₀) = h·(f/A − k·(d₀ + d₁)/2 − c·(v₀ + v₁)/2 + τ·∇²d₀),   d₁ = d₀ + h·(v₀ + v₁)/2
    // The trapezoid makes the foundation and the damping exact in energy: with u = (v₀ + v₁)/2 and Δd = h·u,
    //     ΔE = f·Δd − c·A·u·Δd + ½·Δdᵀ·K_τ·Δd
    // the last term the scheme's share S ≥ 0, the skin's lag (K_τ its part of K), of order (h·ω_τ)² of its energy.
    // (Edges are free: a missing neighbour reads the cell itself, which pulls by nothing.)
    for (std::size_t r = 0; r < rows_; ++r) {
      const std::size_t row = r * columns_;
      const double* here = d + row;
      const double* up = r > 0 ? here - columns_ : here;
      const double* down = r + 1 < rows_ ? here + columns_ : here;
      const double* pushed_N = force_N.data() + row;
      double* speed = v + row;
      double* step_m = moved + row;
      for (std::size_t c = 0; c < columns_; ++c) {
        const double left = here[c > 0 ? c - 1 : c];
        const double right = here[c + 1 < columns_ ? c + 1 : c];
        const double lap = gx * (left + right - 2.0 * here[c]) + gy * (up[c] + down[c] - 2.0 * here[c]);
        const double before = speed[c] * scale;
        speed[c] = (keep * before + h_s * (pushed_N[c] / area_m2 - k * here[c] + lap)) * inverse_diagonal;
        step_m[c] = 0.5 * h_s * (before + speed[c]);
      }
    }
    if (pinned) {
      for (std::size_t i = 0; i < depth_m.size(); ++i) {
        if (std::isnan((*pin_m)[i])) continue;
        v[i] = 0.0;
        moved[i] = 0.0;
      }
    }
    // Depths; the floor stops a cell that reaches it. The skin's ½·Δdᵀ·K_τ·Δd, each pair of neighbours once (the
    // left and the lower one, already moved).
    double work_J = 0.0;
    double damped_J = 0.0;
    double scheme_J = 0.0;
    double kinetic_J = 0.0;
    for (std::size_t r = 0; r < rows_; ++r) {
      const std::size_t row = r * columns_;
      double* step_m = moved + row;
      const double* lower_m = r > 0 ? step_m - columns_ : step_m;
      double* depth = depth_m.data() + row;
      double* speed = v + row;
      const double* pushed_N = force_N.data() + row;
      for (std::size_t c = 0; c < columns_; ++c) {
        double moved_m = step_m[c];
        if (depth[c] + moved_m > max_depth_m_) {
          moved_m = std::max(0.0, max_depth_m_ - depth[c]);
          stopped_J_ += 0.5 * cell_kg * speed[c] * speed[c];
          speed[c] = 0.0;
          step_m[c] = moved_m;
        }
        work_J += pushed_N[c] * moved_m;
        damped_J += moved_m * moved_m;
        depth[c] += moved_m;
        const double across_m = moved_m - step_m[c > 0 ? c - 1 : c];
        const double along_m = moved_m - lower_m[c];
        scheme_J += gx * across_m * across_m + gy * along_m * along_m;
        kinetic_J += speed[c] * speed[c];
      }
    }
    work_J_ += work_J;
    damped_J_ += material_.damping_Paspm * area_m2 * damped_J / h_s;
    scheme_J *= 0.5 * area_m2;
    kinetic_J *= 0.5 * cell_kg;
    // No energy from the scheme: what it added, the speeds give back at the next substep's start, scaled by
    // √(1 − S/K) (K the kinetic energy; S is of order (h·ω)²·K), as a time-domain passivity controller would.
    scheme_J_ += scheme_J;
    scale = 1.0;
    if (scheme_J_ > 0.0 && kinetic_J > 0.0) {
      const double removed_J = std::min(scheme_J_, kinetic_J);
      scale = std::sqrt(1.0 - removed_J / kinetic_J);
      scheme_J_ -= removed_J;
      projected_J_ += removed_J;
    }
  }
  if (scale != 1.0) {
    for (double& speed_mps : velocity_mps_) speed_mps *= scale;
  }
  // Back to exactly nothing once no cell moves or stands out by a picometre: the slab then costs nothing to step.
  constexpr double kRest = 1e-12;
  const auto tiny = [](double x) { return std::abs(x) < kRest; };
  if (!pushed && std::all_of(velocity_mps_.begin(), velocity_mps_.end(), tiny) &&
      std::all_of(depth_m.begin(), depth_m.end(), tiny)) {
    std::fill(velocity_mps_.begin(), velocity_mps_.end(), 0.0);
    std::fill(depth_m.begin(), depth_m.end(), 0.0);
    at_rest_ = true;
  }
  return true;
}

double ElasticMembrane::stored_J(const std::vector<double>& depth_m) const {
  const double area_m2 = cell_x_m_ * cell_y_m_;
  double twice_J = 0.0;
  for (std::size_t r = 0; r < rows_; ++r) {
    for (std::size_t c = 0; c < columns_; ++c) {
      const std::size_t i = r * columns_ + c;
      twice_J += area_m2 * (material_.areal_density_kgpm2 * velocity_mps_[i] * velocity_mps_[i] +
                            material_.stiffness_Papm * depth_m[i] * depth_m[i]);
      // The skin, once per pair: with the right and the upper neighbour.
      if (c + 1 < columns_) {
        const double step_m = depth_m[i + 1] - depth_m[i];
        twice_J += material_.tension_Npm * step_m * step_m * area_m2 / (cell_x_m_ * cell_x_m_);
      }
      if (r + 1 < rows_) {
        const double step_m = depth_m[i + columns_] - depth_m[i];
        twice_J += material_.tension_Npm * step_m * step_m * area_m2 / (cell_y_m_ * cell_y_m_);
      }
    }
  }
  return 0.5 * twice_J;
}

void ElasticMembrane::solve_static_response() {
  // The window reaches the pad's rim plus 14 decay lengths √(τ/k) (e^−14 < 10⁻⁶), at most the slab and 128 cells.
  const double decay_m = std::sqrt(material_.tension_Npm / material_.stiffness_Papm);
  const double reach_m = material_.contact_radius_m + 14.0 * decay_m;
  const double cell_m = std::min(cell_x_m_, cell_y_m_);
  const std::size_t wanted = static_cast<std::size_t>(std::ceil(reach_m / cell_m)) + 1;
  response_half_ = std::max<std::size_t>(1, std::min<std::size_t>({wanted, 128, std::max(columns_, rows_)}));
  const auto side = static_cast<int>(2 * response_half_ + 1);
  const int half = static_cast<int>(response_half_);
  const auto index = [side](int c, int r) { return r * side + c; };
  // (k − τ·∇²)·d = p, zero beyond the window; p the pad's paraboloid of 1 N, normalised over the cells it meets.
  const double gx = material_.tension_Npm / (cell_x_m_ * cell_x_m_);
  const double gy = material_.tension_Npm / (cell_y_m_ * cell_y_m_);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(5 * side * side));
  Eigen::VectorXd pressure_Pa = Eigen::VectorXd::Zero(side * side);
  const double radius2_m2 = material_.contact_radius_m * material_.contact_radius_m;
  double total = 0.0;
  for (int r = 0; r < side; ++r) {
    for (int c = 0; c < side; ++c) {
      const int i = index(c, r);
      entries.emplace_back(i, i, material_.stiffness_Papm + 2.0 * gx + 2.0 * gy);
      if (c > 0) entries.emplace_back(i, index(c - 1, r), -gx);
      if (c + 1 < side) entries.emplace_back(i, index(c + 1, r), -gx);
      if (r > 0) entries.emplace_back(i, index(c, r - 1), -gy);
      if (r + 1 < side) entries.emplace_back(i, index(c, r + 1), -gy);
      const double dx = (c - half) * cell_x_m_;
      const double dy = (r - half) * cell_y_m_;
      const double weight = std::max(0.0, 1.0 - (dx * dx + dy * dy) / radius2_m2);
      pressure_Pa[i] = weight;
      total += weight;
    }
  }
  pressure_Pa /= total * cell_x_m_ * cell_y_m_;
  Eigen::SparseMatrix<double> stiffness(side * side, side * side);
  stiffness.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(stiffness);
  if (solver.info() != Eigen::Success) throw std::runtime_error("elastic slab: the static response did not solve");
  const Eigen::VectorXd depth_m = solver.solve(pressure_Pa);
  response_mpN_.assign(depth_m.data(), depth_m.data() + depth_m.size());
}

double ElasticMembrane::static_response_mpN(double dx_m, double dy_m) const {
  const double half = static_cast<double>(response_half_);
  const double u = dx_m / cell_x_m_ + half;
  const double w = dy_m / cell_y_m_ + half;
  const double last = 2.0 * half;
  if (!(u >= 0.0 && u <= last && w >= 0.0 && w <= last)) return 0.0;
  const auto side = 2 * response_half_ + 1;
  const auto c0 = static_cast<std::size_t>(std::min(u, last - 1.0));
  const auto r0 = static_cast<std::size_t>(std::min(w, last - 1.0));
  const double tu = u - static_cast<double>(c0);
  const double tw = w - static_cast<double>(r0);
  const auto at = [&](std::size_t c, std::size_t r) { return response_mpN_[r * side + c]; };
  return (1.0 - tw) * ((1.0 - tu) * at(c0, r0) + tu * at(c0 + 1, r0)) +
         tw * ((1.0 - tu) * at(c0, r0 + 1) + tu * at(c0 + 1, r0 + 1));
}

}  // namespace impetus
