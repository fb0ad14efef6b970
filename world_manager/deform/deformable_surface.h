// SPDX-License-Identifier: Apache-2.0
#pragma once
// The top face of a static box made of a deformable material (deformable_material.h; paper §6.4;
// docs/deformation.md): a grid of cells, each below the face by its own depth, moved by the material's law once per
// world period: a plastic face dents and stays dented; an elastic one (elastic_membrane.h) moves and springs back.
//
// Frames and units: the slab's body frame (the box's centre, its axes; the top face is z = +half height), metres,
// newton-seconds. Pushes are given in the world frame with the slab's pose. The surface between cell centres is
// bilinear in their depths.
//
// Use, once per world step: press(...) for each stroke of push beyond yield the reports brought (impulse rule) or
// press_by_penetration(...) for each sampled finger (penetration rule), then yield_period(). Not thread-safe; owned by
// the World. Depths are signed for the elastic law (negative: the surface stands out above the face).

#include "common/contract/frames.h"
#include "common/contract/world_view.h"
#include "world_manager/deform/deformable_material.h"
#include "world_manager/deform/elastic_membrane.h"
#include "world_manager/deform/press_path.h"
#include "world_manager/engine/rigid_body_engine.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

namespace impetus {

class DeformableSurface {
 public:
  // `half_size_m`: the box's half extents; `pose`: its fixed pose. Throws std::invalid_argument if the grid would
  // exceed kMaxCells (the scene parser checks first, with the file and key).
  DeformableSurface(const DeformableMaterial& material, const Eigen::Vector3d& half_size_m,
                    const Eigen::Vector3d& position_m, const Eigen::Quaterniond& orientation);

  // The grid's cells: 10^6 (4096 × 256 or 1000 × 1000: a 1 m slab at 1 mm) keeps a world step's yield within
  // milliseconds and its two grids within 16 MB.
  static constexpr std::size_t kMaxCells = 1'000'000;
  static std::size_t cells_for(const DeformableMaterial& material, const Eigen::Vector3d& half_size_m);
  // Elastic: the cells times the substeps a second of simulated time takes (elastic_membrane.h): at 4.5 ns an update
  // (tests/bench/bench_deform.cpp), 10^8 keeps a slab within half of one core in real time (the default gel: 4·10^7).
  static constexpr double kMaxCellStepsPerSecond = 1e8;
  static double cell_steps_per_second(const DeformableMaterial& material, const Eigen::Vector3d& half_size_m);

  // Impulse rule: a stroke's push beyond yield, spread along it (points half a cell apart) and over the contact pad at
  // each, received in this period from endpoint `slot`. A push off the top face's cells is kept where it still meets
  // cells, else counted lost.
  void press(const PressStroke& stroke, std::size_t slot = 0);
  // The whole push a report brought into the slab (N·s, world frame; its part into the top face is counted).
  void absorb(const Eigen::Vector3d& impulse_Ns);
  // Penetration rule: the contact of endpoint `slot` sampled at `finger_m` (world frame; the world passes the finger
  // for a plastic slab, the proxy for an elastic one), over the top face. Plastic: where it is below the surface, the
  // surface under its pad moves in by plasticity × the penetration, paraboloid-shaped (the centre by all of it).
  // Elastic: the cells under its pad are held, over the coming period, where the contact puts them (paraboloid-shaped
  // to its depth below the undented face), the rest of the gel following: a world that samples where the finger is.
  void press_by_penetration(const Eigen::Vector3d& finger_m, std::size_t slot = 0);
  // The law (deformable_material.h) over the pushes received since the last call: plastic, the dent they make;
  // elastic, the surface moved over the coming world period of `period_s` by them as a force spread over it.
  void yield_period(double period_s = 0.0);

  // The surface's height above the body's centre at body-frame (x, y), clamped to the face: the top minus the dent.
  double height_m(double x_m, double y_m) const;
  // How much further in the surface at body-frame (x, y) can go before the slab's unyielding floor.
  double room_m(double x_m, double y_m) const {
    return std::max(0.0, height_m(x_m, y_m) - (half_size_m_.z() - max_depth_m_));
  }
  // Whether a body-frame point lies over the top face (within its edges) and above the slab's bottom: there the
  // surface is this grid's, not the box's (a finger that came in over the top, however deep, is pushed back up, never
  // out through the bottom).
  bool over_face(const Eigen::Vector3d& body_m) const;
  // The surface under a body-frame point over the face: the point on it straight below or above, and its unit
  // outward normal (from the bilinear surface's slope), both in the world frame.
  void tangent_plane(const Eigen::Vector3d& body_m, Eigen::Vector3d& point_m, Eigen::Vector3d& normal) const;
  Eigen::Vector3d to_body(const Eigen::Vector3d& world_m) const;
  // The heights about a body-frame point over the face (common/contract/frames.h DentPatch), for object `object_id`:
  // a cell apart, or further apart where that is needed to reach `half_span_m` each way (where the proxy may go
  // before the next frame: a finger beyond the patch meets only the plane sent).
  // Elastic: the heights are the surface's without endpoint `slot`'s own share of it (the same law driven by its
  // pushes alone; the law is linear), since the haptic side puts back the static response to the finger's present
  // push itself, at 1 kHz (haptic_controller/local_yield.h): the finger's own press is not felt twice, nor a period
  // late, nor fed back through the world's gel, whose pad of a few grams on the haptic spring would ring.
  void patch_about(const Eigen::Vector3d& body_m, std::int32_t object_id, double half_span_m, DentPatch& patch,
                   std::size_t slot = 0) const;

  // The surface for the engine, bodies resting on it (engine/rigid_body_engine.h DentedTop): the cells' heights,
  // kept in place for this surface's life.
  DentedTop dented_top() const;
  // The dent to draw (common/contract/world_view.h ViewDent) for object `object_id`: the dented cells' rectangle,
  // a cell a point while it fits in kMaxViewDentSide, the deepest cell of each block beyond (a groove narrower than a
  // block still shows). Leaves `out` without an object (object_id −1) while nothing is dented.
  void view_dent(std::int32_t object_id, ViewDent& out) const;
  // Counts the steps that changed the surface (a cell went deeper): the engine needs the heights again only then.
  std::uint64_t changes() const { return changes_; }

  const DeformableMaterial& material() const { return material_; }
  double dent_m() const { return dent_m_; }             // the deepest cell now
  double max_dent_m() const { return max_dent_m_; }     // the deepest any cell has been
  double dent_volume_m3() const { return volume_m3_; }  // Σ depth·area over the cells, now
  // Elastic: the depth under the pad's centre per newton of steady push (ElasticMembrane::compliance_mpN); 0 plastic.
  double compliance_mpN() const { return membrane_ ? membrane_->compliance_mpN() : 0.0; }
  // Elastic: the energy books (elastic_membrane.h): the work the pushes did, what damping and the floor took, what
  // the surface holds now, the integrator's net share (≤ 0) and what its passivity observer gave back. Zero for the
  // plastic law, whose dent volume is its check.
  double work_J() const { return membrane_ ? membrane_->work_J() : 0.0; }
  double dissipated_J() const { return membrane_ ? membrane_->damped_J() + membrane_->stopped_J() : 0.0; }
  double stored_J() const { return membrane_ ? membrane_->stored_J(depth_m_) : 0.0; }
  double scheme_J() const { return membrane_ ? membrane_->scheme_J() : 0.0; }
  double given_back_J() const { return membrane_ ? membrane_->given_back_J() : 0.0; }
  // The row of cells through the deepest one (along body x): a groove's profile. `y_m` its body-frame y, `x0_m` the
  // first cell centre's x, `dx_m` the cell edge; `depth_m` one value per column.
  struct Profile {
    double y_m = 0.0;
    double x0_m = 0.0;
    double dx_m = 0.0;
    std::vector<double> depth_m;
  };
  Profile deepest_row() const;
  double absorbed_Ns() const { return absorbed_Ns_; }             // all the push into the top face (absorb)
  double yielding_Ns() const { return pressed_Ns_; }              // the push beyond yield it dented by (press)
  double lost_Ns() const { return lost_Ns_; }                     // pushed where no cell is
  double clamped_m3() const { return clamped_m3_; }               // volume the unyielding floor of the slab refused
  std::size_t columns() const { return columns_; }
  std::size_t rows() const { return rows_; }
  double depth_m(std::size_t column, std::size_t row) const { return depth_m_[row * columns_ + column]; }

 private:
  // Spreads `amount` over the pad around body-frame (x, y) into `grid` by the paraboloid's weights, normalised over
  // the cells it meets; returns false if it meets none.
  bool spread(double x_m, double y_m, double amount, std::vector<double>& grid, bool touch);
  void deepen(std::size_t cell, double by_m);
  // Widens the dented rectangle to take in a cell.
  void mark_dented(std::size_t column, std::size_t row);
  // Elastic: after the membrane moved, the tops, the deepest, the volume and the moved rectangle again.
  void remeasure();
  // Bilinear in `grid`'s cell values between their centres, constant beyond the outer centres.
  double value_at(const std::vector<double>& grid, double x_m, double y_m) const;
  // Elastic: endpoint `slot`'s own share of the surface (created at its first push).
  struct OwnShare {
    std::unique_ptr<ElasticMembrane> membrane;
    std::vector<double> depth_m;
    std::vector<double> received_Ns;
    std::vector<double> force_N;
    std::vector<double> pin_m;
  };
  // nullptr while `slot` is the only endpoint that pushed (its share is then the whole surface).
  OwnShare* own(std::size_t slot);
  // Elastic, penetration rule: the pins under a contact at body-frame `body_m` into `pin_m` (NaN: not pinned).
  void pin_under(const Eigen::Vector3d& body_m, std::vector<double>& pin_m) const;

  DeformableMaterial material_;
  Eigen::Vector3d half_size_m_;
  Eigen::Vector3d position_m_;
  Eigen::Quaterniond orientation_;
  std::size_t columns_ = 0;  // along body x
  std::size_t rows_ = 0;     // along body y
  double cell_x_m_ = 0.0;
  double cell_y_m_ = 0.0;
  double max_depth_m_ = 0.0;
  std::unique_ptr<ElasticMembrane> membrane_;  // the elastic law's; nullptr for the plastic
  std::vector<OwnShare> own_;                  // elastic: per endpoint slot, once two have pushed (shared_)
  std::optional<std::size_t> solo_;            // elastic: the one endpoint that pushed, until a second does
  bool shared_ = false;
  std::vector<double> force_N_;                // elastic: scratch, the force per cell over the coming period
  std::vector<double> pin_m_;                  // elastic, penetration rule: this period's pins (NaN: free)
  bool pinned_ = false;                        // a pin was set since the last yield_period
  std::vector<double> depth_m_;    // per cell, ≥ 0 plastic
  std::vector<double> top_m_;      // per cell, the height above the centre: half height − depth (dented_top)
  double lowest_m_ = 0.0;          // the lowest of top_m_
  // The dented cells lie within [dented_column_lo_, dented_column_hi_] × [dented_row_lo_, dented_row_hi_] (if any).
  bool dented_ = false;
  std::size_t dented_column_lo_ = 0, dented_column_hi_ = 0, dented_row_lo_ = 0, dented_row_hi_ = 0;
  std::uint64_t changes_ = 0;
  bool changed_ = false;           // a cell went deeper since the last yield_period or press_by_penetration
  std::vector<double> received_Ns_;  // per cell, this period
  std::vector<double> weights_;      // scratch for spread()
  // The cells received_Ns_ may be nonzero in, if touched_: [column_lo, column_hi] × [row_lo, row_hi].
  bool touched_ = false;
  std::size_t column_lo_ = 0, column_hi_ = 0, row_lo_ = 0, row_hi_ = 0;
  double pressed_Ns_ = 0.0;
  double absorbed_Ns_ = 0.0;
  double lost_Ns_ = 0.0;
  double clamped_m3_ = 0.0;
  double dent_m_ = 0.0;      // plastic depths only grow, so these are kept as they grow; elastic ones remeasured
  double max_dent_m_ = 0.0;
  double volume_m3_ = 0.0;
};

}  // namespace impetus
