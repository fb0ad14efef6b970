// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/mesh_bvh.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

namespace impetus {

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c, std::uint8_t& feature) {
  // Voronoi regions of the triangle, tested in turn with barycentric coordinates from dot products (Ericson,
  // "Real-Time Collision Detection", 5.1.5): a vertex, an edge, or the face's interior.
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    feature = 4;
    return a;
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    feature = 5;
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    feature = 1;
    return a + (d1 / (d1 - d3)) * ab;
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    feature = 6;
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    feature = 3;
    return a + (d2 / (d2 - d6)) * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    feature = 2;
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  feature = 0;
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

MeshBvh::MeshBvh(TriangleMesh mesh) : mesh_(std::move(mesh)) {
  const std::size_t n = mesh_.triangles.size();
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0u);
  std::vector<Eigen::Vector3d> centroids(n);
  for (std::size_t t = 0; t < n; ++t) {
    const auto& tri = mesh_.triangles[t];
    centroids[t] = (mesh_.vertices_m[tri[0]] + mesh_.vertices_m[tri[1]] + mesh_.vertices_m[tri[2]]) / 3.0;
  }
  nodes_.reserve(n > 0 ? 2 * (n / kLeafTriangles + 1) : 1);
  if (n == 0) {
    nodes_.push_back(Node{});
  } else {
    build(0, static_cast<std::uint32_t>(n), centroids, 0);
  }
  pseudo_normals();
  if (n > 0 && nodes_.front().count == 0) {
    widen(0);
    wide_.shrink_to_fit();  // grown by doubling: hold only what the tree uses
  } else {  // no triangles, or a root that is a leaf: one wide node whose one child is that leaf, its box everywhere
    WideNode root = childless();
    if (n > 0) {
      constexpr float kAll = std::numeric_limits<float>::infinity();
      root.min_x[0] = root.min_y[0] = root.min_z[0] = -kAll;
      root.max_x[0] = root.max_y[0] = root.max_z[0] = kAll;
      root.child[0] = nodes_.front().first;
      root.count[0] = nodes_.front().count;
    }
    wide_.push_back(root);
  }
}

namespace {

// A double rounded to the float at or below it, or at or above it: a float box holds the double one.
float float_down(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f;
}
float float_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

}  // namespace

MeshBvh::WideNode MeshBvh::childless() {
  WideNode node;
  node.child.fill(0);
  node.count.fill(kNone);
  for (auto* low : {&node.min_x, &node.min_y, &node.min_z}) low->fill(1.0f);  // empty boxes: min above max
  for (auto* high : {&node.max_x, &node.max_y, &node.max_z}) high->fill(-1.0f);
  return node;
}

std::uint32_t MeshBvh::widen(std::uint32_t node) {
  const auto index = static_cast<std::uint32_t>(wide_.size());
  wide_.emplace_back();
  // The children that are leaves, and the grandchildren under those that are not.
  std::array<std::uint32_t, 4> entries{};
  std::size_t used = 0;
  for (const std::uint32_t c : {node + 1, nodes_[node].first}) {
    if (nodes_[c].count > 0) {
      entries[used++] = c;
    } else {
      entries[used++] = c + 1;
      entries[used++] = nodes_[c].first;
    }
  }
  WideNode wide = childless();
  for (std::size_t k = 0; k < used; ++k) {
    const Node& entry = nodes_[entries[k]];
    wide.min_x[k] = float_down(entry.bounds.min().x());
    wide.min_y[k] = float_down(entry.bounds.min().y());
    wide.min_z[k] = float_down(entry.bounds.min().z());
    wide.max_x[k] = float_up(entry.bounds.max().x());
    wide.max_y[k] = float_up(entry.bounds.max().y());
    wide.max_z[k] = float_up(entry.bounds.max().z());
    if (entry.count > 0) {
      wide.child[k] = entry.first;
      wide.count[k] = entry.count;
    } else {
      wide.child[k] = widen(entries[k]);
      wide.count[k] = kInner;
    }
  }
  wide_[index] = wide;  // after the recursion, which may have moved the array
  return index;
}

std::uint32_t MeshBvh::build(std::uint32_t begin, std::uint32_t end, std::vector<Eigen::Vector3d>& centroids,
                             int depth) {
  const auto index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back(Node{});
  Eigen::AlignedBox3d bounds, centre_bounds;
  for (std::uint32_t i = begin; i < end; ++i) {
    const auto& tri = mesh_.triangles[order_[i]];
    for (std::uint32_t v : tri) bounds.extend(mesh_.vertices_m[v]);
    centre_bounds.extend(centroids[order_[i]]);
  }
  nodes_[index].bounds = bounds;
  // A leaf when few triangles are left, or all their centres coincide, or the tree is as deep as a query's stack.
  const Eigen::Vector3d spread = centre_bounds.sizes();
  int axis = 0;
  spread.maxCoeff(&axis);
  if (end - begin <= kLeafTriangles || !(spread[axis] > 0.0) || depth + 1 >= static_cast<int>(kMaxDepth)) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  // Median split along the widest spread of centres: a balanced tree, depth log2(n / 4).
  const std::uint32_t middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](std::uint32_t x, std::uint32_t y) { return centroids[x][axis] < centroids[y][axis]; });
  build(begin, middle, centroids, depth + 1);
  const std::uint32_t right = build(middle, end, centroids, depth + 1);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

void MeshBvh::pseudo_normals() {
  const std::size_t n = mesh_.triangles.size();
  const std::vector<Eigen::Vector3d> faces = face_normals(mesh_);
  face_normals_.assign(faces.begin(), faces.end());
  edge_normals_.assign(n, {});
  const std::vector<Eigen::Vector3d> vertices = angle_weighted_normals(mesh_, faces);
  vertex_normals_.assign(vertices.begin(), vertices.end());
  // An edge's pseudo-normal is the sum of its two faces' normals (one face's at an open edge): the edges are matched
  // by their sorted vertex pair.
  struct Use {
    std::uint64_t key;
    std::uint32_t triangle;
    std::uint8_t edge;
  };
  std::vector<Use> uses;
  uses.reserve(3 * n);
  for (std::size_t t = 0; t < n; ++t) {
    const auto& tri = mesh_.triangles[t];
    for (std::uint8_t e = 0; e < 3; ++e) {
      const std::uint64_t lo = std::min(tri[e], tri[(e + 1) % 3]), hi = std::max(tri[e], tri[(e + 1) % 3]);
      uses.push_back({(lo << 32) | hi, static_cast<std::uint32_t>(t), e});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const Use& x, const Use& y) { return x.key < y.key; });
  // Rounding in a plane's height at a corner: far below any bend a mesh is built with.
  const double flat_m = 1e-12 * nodes_.front().bounds.diagonal().norm();
  locally_convex_ = n > 0;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (j < uses.size() && uses[j].key == uses[i].key) sum += face_normals_[uses[j++].triangle];
    if (sum.norm() > 0.0) sum.normalize();
    for (std::size_t k = i; k < j; ++k) {
      edge_normals_[uses[k].triangle][uses[k].edge] = sum.norm() > 0.0 ? sum : face_normals_[uses[k].triangle];
    }
    // Convex at this edge: the second face's far corner is behind (or on, to rounding) the first face's plane. An
    // edge of one face (open) or of more than two is not.
    if (j - i != 2) {
      locally_convex_ = false;
    } else {
      const Use& first = uses[i];
      const Use& second = uses[i + 1];
      const Eigen::Vector3d& far_m = mesh_.vertices_m[mesh_.triangles[second.triangle][(second.edge + 2) % 3]];
      const Eigen::Vector3d& on_first_m = mesh_.vertices_m[mesh_.triangles[first.triangle][0]];
      if (face_normals_[first.triangle].dot(far_m - on_first_m) > flat_m) locally_convex_ = false;
    }
    i = j;
  }
}

bool MeshBvh::nearest(const Eigen::Vector3d& query_m, MeshPoint& out) const {
  return nearest_within(query_m, std::numeric_limits<double>::infinity(), out);
}

bool MeshBvh::nearest_within(const Eigen::Vector3d& query_m, double max_distance_m, MeshPoint& out) const {
  if (mesh_.triangles.empty()) return false;
  return search(query_m, max_distance_m * max_distance_m, false, Eigen::Vector3d::Zero(), 0, 0, out);
}

bool MeshBvh::nearest_from(const Eigen::Vector3d& query_m, const MeshPoint& hint, MeshPoint& out) const {
  if (mesh_.triangles.empty()) return false;
  if (hint.triangle >= mesh_.triangles.size()) return nearest(query_m, out);
  std::uint8_t feature = 0;
  const Eigen::Vector3d p = closest_on(hint.triangle, query_m, feature);
  return search(query_m, (query_m - p).squaredNorm(), true, p, hint.triangle, feature, out);
}

bool MeshBvh::search(const Eigen::Vector3d& query_m, double best_squared, bool seeded, Eigen::Vector3d best_point,
                     std::uint32_t best_triangle, std::uint8_t best_feature, MeshPoint& out) const {
  bool found = seeded;
  // Depth-first, nearer child first; a box no nearer than the best point so far is skipped with all it holds.
  std::array<std::uint32_t, kMaxDepth + 1> stack{};
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t self = stack[--top];
    const Node& node = nodes_[self];
    if (node.bounds.squaredExteriorDistance(query_m) > best_squared) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const std::uint32_t t = order_[i];
        std::uint8_t feature = 0;
        const Eigen::Vector3d p = closest_on(t, query_m, feature);
        const double squared = (query_m - p).squaredNorm();
        if (squared <= best_squared) {
          best_squared = squared;
          best_point = p;
          best_triangle = t;
          best_feature = feature;
          found = true;
        }
      }
      continue;
    }
    const std::uint32_t left = self + 1, right = node.first;
    const double to_left = nodes_[left].bounds.squaredExteriorDistance(query_m);
    const double to_right = nodes_[right].bounds.squaredExteriorDistance(query_m);
    // Pushed farther first, so the nearer is taken next. The depth is below kMaxDepth by construction.
    if (to_left <= to_right) {
      stack[top++] = right;
      stack[top++] = left;
    } else {
      stack[top++] = left;
      stack[top++] = right;
    }
  }
  if (!found) return false;
  out = answer(query_m, best_point, best_squared, best_triangle, best_feature);
  return true;
}

Eigen::Vector3d MeshBvh::closest_on(std::uint32_t t, const Eigen::Vector3d& query_m, std::uint8_t& feature) const {
  const auto& tri = mesh_.triangles[t];
  return closest_point_on_triangle(query_m, mesh_.vertices_m[tri[0]], mesh_.vertices_m[tri[1]],
                                   mesh_.vertices_m[tri[2]], feature);
}

MeshPoint MeshBvh::answer(const Eigen::Vector3d& query_m, const Eigen::Vector3d& point, double squared,
                          std::uint32_t triangle, std::uint8_t feature) const {
  const Eigen::Vector3d& normal = feature == 0   ? face_normals_[triangle]
                                  : feature <= 3 ? edge_normals_[triangle][feature - 1]
                                                 : vertex_normals_[mesh_.triangles[triangle][feature - 4]];
  const double distance_m = std::sqrt(squared);
  MeshPoint out;
  out.point_m = point;
  out.normal = normal;
  out.signed_distance_m = (query_m - point).dot(normal) < 0.0 ? -distance_m : distance_m;
  out.triangle = triangle;
  out.feature = feature;
  return out;
}

int MeshBvh::within(const Eigen::Vector3d& query_m, double radius_m, std::span<MeshPoint> out) const {
  if (mesh_.triangles.empty() || out.empty()) return 0;
  const double radius_squared = radius_m * radius_m;
  std::array<double, 64> kept_squared{};  // out's points' squared distances, for replacing the farthest
  const std::size_t capacity = std::min(out.size(), kept_squared.size());
  std::size_t count = 0;
  std::array<std::uint32_t, kMaxDepth + 1> stack{};
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t self = stack[--top];
    const Node& node = nodes_[self];
    if (node.bounds.squaredExteriorDistance(query_m) > radius_squared) continue;
    if (node.count == 0) {
      stack[top++] = node.first;
      stack[top++] = self + 1;
      continue;
    }
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
      const std::uint32_t t = order_[i];
      std::uint8_t feature = 0;
      const Eigen::Vector3d p = closest_on(t, query_m, feature);
      const double squared = (query_m - p).squaredNorm();
      if (squared > radius_squared) continue;
      std::size_t slot = count;
      if (count == capacity) {  // full: in place of the farthest, if nearer
        slot = static_cast<std::size_t>(std::max_element(kept_squared.begin(), kept_squared.begin() + count) -
                                        kept_squared.begin());
        if (squared >= kept_squared[slot]) continue;
      } else {
        ++count;
      }
      kept_squared[slot] = squared;
      out[slot] = answer(query_m, p, squared, t, feature);
    }
  }
  // Nearest first (insertion: a handful of points).
  for (std::size_t i = 1; i < count; ++i) {
    for (std::size_t j = i; j > 0 && kept_squared[j] < kept_squared[j - 1]; --j) {
      std::swap(kept_squared[j], kept_squared[j - 1]);
      std::swap(out[j], out[j - 1]);
    }
  }
  return static_cast<int>(count);
}

namespace {

// The segment a + t·d, t in [0, 1], clipped to the box by the slab method: whether any of it lies in the box.
bool segment_meets_box(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& a, const Eigen::Vector3d& d) {
  double t0 = 0.0, t1 = 1.0;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (a[i] < box.min()[i] || a[i] > box.max()[i]) return false;
      continue;
    }
    double near = (box.min()[i] - a[i]) / d[i];
    double far = (box.max()[i] - a[i]) / d[i];
    if (near > far) std::swap(near, far);
    t0 = std::max(t0, near);
    t1 = std::min(t1, far);
    if (t0 > t1) return false;
  }
  return true;
}

// Möller–Trumbore: the parameter t at which a + t·d meets triangle pqr, or −1 if it does not (parallel, or
// outside the triangle's edges).
double segment_meets_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& d, const Eigen::Vector3d& p,
                              const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
  const Eigen::Vector3d e1 = q - p, e2 = r - p;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return -1.0;
  const double inverse = 1.0 / det;
  const Eigen::Vector3d s = a - p;
  const double u = inverse * s.dot(h);
  if (u < 0.0 || u > 1.0) return -1.0;
  const Eigen::Vector3d k = s.cross(e1);
  const double v = inverse * d.dot(k);
  if (v < 0.0 || u + v > 1.0) return -1.0;
  return inverse * e2.dot(k);
}

}  // namespace

bool MeshBvh::segment_crosses(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double t_min) const {
  if (nodes_.empty()) return false;
  const Eigen::Vector3d d = b - a;
  std::array<std::uint32_t, kMaxDepth + 1> stack{};
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!segment_meets_box(node.bounds, a, d)) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
        const auto& tri = mesh_.triangles[order_[i]];
        const double t = segment_meets_triangle(a, d, mesh_.vertices_m[tri[0]], mesh_.vertices_m[tri[1]],
                                                mesh_.vertices_m[tri[2]]);
        if (t > t_min && t <= 1.0) return true;
      }
      continue;
    }
    const std::uint32_t self = static_cast<std::uint32_t>(&node - nodes_.data());
    stack[top++] = node.first;  // right
    stack[top++] = self + 1;    // left
  }
  return false;
}

bool MeshBvh::first_entry(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tolerance_m,
                          const std::uint32_t* skip, int skip_count, MeshEntry& out) const {
  if (mesh_.triangles.empty()) return false;
  const Eigen::Vector3d d = b - a;
  // The slab method per lane, in doubles: an axis the way does not move along is crossed at no t, and there the way
  // is in the slab or not at all (a huge 1/d would give inf·0).
  std::array<double, 3> inverse{};
  std::array<bool, 3> along{};
  for (int i = 0; i < 3; ++i) {
    const auto axis = static_cast<std::size_t>(i);
    along[axis] = d[i] != 0.0;
    inverse[axis] = along[axis] ? 1.0 / d[i] : 0.0;
  }
  // Nearest box first, and a box the way enters later than the best crossing so far is skipped with all it holds: a
  // crossing lies within tolerance_m of its triangle, so within that much of every box holding it, and is entered no
  // earlier than that box. Ties go to the lower leaf position, so the answer does not depend on the order the boxes
  // are taken in.
  double best_t = std::numeric_limits<double>::infinity();
  std::uint32_t best_position = 0;
  const auto test_leaf = [&](std::uint32_t first, std::uint32_t count) {
    for (std::uint32_t i = first; i < first + count; ++i) {
      const std::uint32_t triangle = order_[i];
      if (std::find(skip, skip + skip_count, triangle) != skip + skip_count) continue;
      const auto& tri = mesh_.triangles[triangle];
      const Eigen::Vector3d& p = mesh_.vertices_m[tri[0]];
      const Eigen::Vector3d& n = face_normals_[triangle];
      const double height_a_m = n.dot(a - p);
      const double height_b_m = n.dot(b - p);
      if (height_a_m < -tolerance_m || height_b_m >= -tolerance_m) continue;  // not from in front to behind
      // Where the way meets the plane; a start on it to rounding (slightly behind) meets it at once.
      const double t = height_a_m > 0.0 ? height_a_m / (height_a_m - height_b_m) : 0.0;
      if (t > best_t || (t == best_t && i > best_position)) continue;
      const Eigen::Vector3d x = a + t * d;
      if (!within_edges(triangle, x, tolerance_m)) continue;
      best_t = t;
      best_position = i;
      out.point_m = x;
      out.normal = n;
      out.t = t;
      out.triangle = triangle;
    }
  };
  struct Pending {
    std::uint32_t node;
    double t_enter;
  };
  std::array<Pending, 3 * kMaxDepth + 4> stack;  // up to three pushed a level, half as many levels as the binary tree
  std::size_t top = 0;
  stack[top++] = {0, 0.0};
  while (top > 0) {
    const Pending pending = stack[--top];
    if (pending.t_enter > best_t) continue;
    const WideNode& node = wide_[pending.node];
    const double t_max = std::min(1.0, best_t);
    // The four boxes, grown by the tolerance, at once: t0 the latest entry, t1 the earliest exit, over the slabs.
    std::array<double, 4> t0{}, t1{};
    std::array<bool, 4> outside{};
    const std::array<const std::array<float, 4>*, 3> low{&node.min_x, &node.min_y, &node.min_z};
    const std::array<const std::array<float, 4>*, 3> high{&node.max_x, &node.max_y, &node.max_z};
    for (std::size_t k = 0; k < 4; ++k) {
      t0[k] = 0.0;
      t1[k] = t_max;
    }
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (along[axis]) {
        for (std::size_t k = 0; k < 4; ++k) {
          const auto i = static_cast<Eigen::Index>(axis);
          const double near = (static_cast<double>((*low[axis])[k]) - tolerance_m - a[i]) * inverse[axis];
          const double far = (static_cast<double>((*high[axis])[k]) + tolerance_m - a[i]) * inverse[axis];
          t0[k] = std::max(t0[k], std::min(near, far));
          t1[k] = std::min(t1[k], std::max(near, far));
        }
      } else {
        const double at = a[static_cast<Eigen::Index>(axis)];
        for (std::size_t k = 0; k < 4; ++k) {
          outside[k] = outside[k] || at < static_cast<double>((*low[axis])[k]) - tolerance_m ||
                       at > static_cast<double>((*high[axis])[k]) + tolerance_m;
        }
      }
    }
    std::array<std::pair<double, std::size_t>, 4> hits;
    int hit_count = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      if (node.count[k] == kNone || outside[k] || t0[k] > t1[k]) continue;
      hits[static_cast<std::size_t>(hit_count++)] = {t0[k], k};
    }
    for (int h = 1; h < hit_count; ++h) {  // at most four: by insertion, nearest first
      for (int g = h; g > 0 && hits[static_cast<std::size_t>(g)] < hits[static_cast<std::size_t>(g - 1)]; --g) {
        std::swap(hits[static_cast<std::size_t>(g)], hits[static_cast<std::size_t>(g - 1)]);
      }
    }
    // Leaves at once, nearest first; wide nodes pushed farthest first, so the nearest is taken next.
    for (int h = 0; h < hit_count; ++h) {
      const auto [t, k] = hits[static_cast<std::size_t>(h)];
      if (node.count[k] != kInner && !(t > best_t)) test_leaf(node.child[k], node.count[k]);
    }
    for (int h = hit_count - 1; h >= 0; --h) {
      const auto [t, k] = hits[static_cast<std::size_t>(h)];
      if (node.count[k] == kInner && !(t > best_t)) stack[top++] = {node.child[k], t};
    }
  }
  return best_t <= 1.0;
}

bool MeshBvh::within_edges(std::uint32_t triangle, const Eigen::Vector3d& x, double tolerance_m) const {
  // On the inner side of each edge, or less than tolerance_m outside it: (e × (x − v))·n is the edge's length times
  // x's distance inside it.
  const auto& tri = mesh_.triangles[triangle];
  const Eigen::Vector3d& n = face_normals_[triangle];
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& from = mesh_.vertices_m[tri[k]];
    const Eigen::Vector3d edge = mesh_.vertices_m[tri[(k + 1) % 3]] - from;
    if (edge.cross(x - from).dot(n) < -tolerance_m * edge.norm()) return false;
  }
  return true;
}

bool MeshBvh::on_triangle(std::uint32_t triangle, const Eigen::Vector3d& x, double tolerance_m,
                          MeshEntry& out) const {
  if (triangle >= mesh_.triangles.size()) return false;
  const Eigen::Vector3d& n = face_normals_[triangle];
  const double height_m = n.dot(x - mesh_.vertices_m[mesh_.triangles[triangle][0]]);
  if (std::abs(height_m) > tolerance_m || !within_edges(triangle, x, tolerance_m)) return false;
  out.point_m = x - height_m * n;
  out.normal = n;
  out.t = 0.0;
  out.triangle = triangle;
  return true;
}

std::size_t MeshBvh::memory_bytes() const {
  return mesh_.vertices_m.capacity() * sizeof(Eigen::Vector3d) +
         mesh_.triangles.capacity() * sizeof(mesh_.triangles[0]) + nodes_.capacity() * sizeof(Node) +
         wide_.capacity() * sizeof(WideNode) + order_.capacity() * sizeof(std::uint32_t) +
         face_normals_.capacity() * sizeof(Eigen::Vector3d) + edge_normals_.capacity() * sizeof(edge_normals_[0]) +
         vertex_normals_.capacity() * sizeof(Eigen::Vector3d);
}

}  // namespace impetus
