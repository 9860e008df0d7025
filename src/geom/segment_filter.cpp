// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/segment_filter.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "fiberfluid/geom/certified_sign.hpp"

namespace fiberfluid::geom {

namespace {

constexpr int kLeafFaces = 4;

bool has_vertex(const int* v, int i) { return v[0] == i || v[1] == i || v[2] == i; }

// Where a line goes against a triangle, from the certified signs of the
// volumes it spans with the three edges: mixed signs put it beside the
// closed triangle, equal non-zero ones through its interior.
enum class LineAtTriangle { Beside, Through, Unsure };

LineAtTriangle line_at_triangle(int e0, int e1, int e2) {
  const bool seen_positive = e0 > 0 || e1 > 0 || e2 > 0, seen_negative = e0 < 0 || e1 < 0 || e2 < 0;
  if (seen_positive && seen_negative) return LineAtTriangle::Beside;
  if (e0 == 0 || e1 == 0 || e2 == 0) return LineAtTriangle::Unsure;
  return LineAtTriangle::Through;
}

}  // namespace

SegmentFilter::SegmentFilter(const Surface& s, std::vector<Star> stars)
    : surface_(s), stars_(std::move(stars)), incident_(static_cast<size_t>(s.num_vertices())) {
  double largest = 0.0;
  for (int i = 0; i < s.num_vertices(); ++i)
    for (int k = 0; k < 3; ++k) {
      usable_ &= coordinate_in_filter_range(s.V(i, k));
      largest = std::max(largest, std::abs(s.V(i, k)));
    }
  if (!usable_) return;
  // The slab test's rounding is relative to the coordinates' size; boxes
  // grown by far more than that never lose a face the segment meets.
  margin_ = 1e-9 * largest;
  reach_ = 4.0 * largest;
  std::vector<Face> faces(static_cast<size_t>(s.num_faces()));
  for (int f = 0; f < s.num_faces(); ++f) {
    Face& face = faces[static_cast<size_t>(f)];
    double* corner[3] = {face.a, face.b, face.c};
    for (int k = 0; k < 3; ++k) {
      face.v[k] = s.F(f, k);
      for (int x = 0; x < 3; ++x) corner[k][x] = s.V(face.v[k], x);
    }
  }
  std::vector<int> order(faces.size());
  std::iota(order.begin(), order.end(), 0);
  nodes_.reserve(2 * order.size() / kLeafFaces + 2);
  build(order, faces, 0, static_cast<int>(order.size()));
  faces_.reserve(order.size());
  for (int f : order) faces_.push_back(faces[static_cast<size_t>(f)]);
  for (size_t position = 0; position < faces_.size(); ++position)
    for (int v : faces_[position].v)
      incident_[static_cast<size_t>(v)].push_back(static_cast<int>(position));
}

// Median split along the longest axis of the face centroids' box.
void SegmentFilter::build(std::vector<int>& order, const std::vector<Face>& faces, int begin,
                          int end) {
  const size_t at = nodes_.size();
  nodes_.push_back(
      Node{{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}, begin, begin, 0});
  double centre_lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL},
         centre_hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (int k = begin; k < end; ++k) {
    const Face& f = faces[static_cast<size_t>(order[static_cast<size_t>(k)])];
    for (int x = 0; x < 3; ++x) {
      Node& node = nodes_[at];
      node.lo[x] = std::min({node.lo[x], f.a[x], f.b[x], f.c[x]});
      node.hi[x] = std::max({node.hi[x], f.a[x], f.b[x], f.c[x]});
      const double centre = (f.a[x] + f.b[x] + f.c[x]) / 3.0;
      centre_lo[x] = std::min(centre_lo[x], centre);
      centre_hi[x] = std::max(centre_hi[x], centre);
    }
  }
  for (int x = 0; x < 3; ++x) {
    nodes_[at].lo[x] -= margin_;
    nodes_[at].hi[x] += margin_;
  }
  if (end - begin <= kLeafFaces) {
    nodes_[at].end = end;
  } else {
    int axis = 0;
    for (int x = 1; x < 3; ++x)
      if (centre_hi[x] - centre_lo[x] > centre_hi[axis] - centre_lo[axis]) axis = x;
    const int middle = begin + (end - begin) / 2;
    auto centre = [&](int f) {
      const Face& face = faces[static_cast<size_t>(f)];
      return face.a[axis] + face.b[axis] + face.c[axis];
    };
    std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end,
                     [&](int f, int g) { return centre(f) < centre(g); });
    build(order, faces, begin, middle);
    build(order, faces, middle, end);
  }
  nodes_[at].skip = static_cast<int>(nodes_.size());
}

SegmentFilter::Segment::Segment(const double* from, const double* to) {
  for (int x = 0; x < 3; ++x) {
    start[x] = from[x];
    const double d = to[x] - from[x];
    // A zero component's slab is a containment test; an infinite inverse
    // would make 0 * inf there.
    parallel[x] = d == 0.0;
    inverse[x] = parallel[x] ? 0.0 : 1.0 / d;
  }
}

bool SegmentFilter::crosses_box(const Node& node, const Segment& segment) const {
  double t_in = 0.0, t_out = 1.0;
  for (int x = 0; x < 3; ++x) {
    if (segment.parallel[x]) {
      if (segment.start[x] < node.lo[x] || segment.start[x] > node.hi[x]) return false;
      continue;
    }
    double t0 = (node.lo[x] - segment.start[x]) * segment.inverse[x],
           t1 = (node.hi[x] - segment.start[x]) * segment.inverse[x];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  return t_in <= t_out;
}

template <class Visit>
bool SegmentFilter::for_each_face_along(const Segment& segment, Visit&& visit) const {
  for (size_t k = 0; k < nodes_.size();) {
    const Node& node = nodes_[k];
    if (!crosses_box(node, segment)) {
      k = static_cast<size_t>(node.skip);
      continue;
    }
    for (int f = node.begin; f < node.end; ++f)
      if (!visit(faces_[static_cast<size_t>(f)])) return false;
    ++k;
  }
  return true;
}

int SegmentFilter::starts_inside(int v, const double* x) const {
  bool any_front = false, all_front = true;
  for (int f : incident_[static_cast<size_t>(v)]) {
    const Face& face = faces_[static_cast<size_t>(f)];
    const int sign = certified_orientation(face.a, face.b, face.c, x);
    if (sign == 0) return 2;
    any_front |= sign > 0;
    all_front &= sign > 0;
  }
  // A convex cone is the intersection of its faces' half-spaces; a concave
  // star's outside is the intersection of the opposite ones.
  switch (stars_[static_cast<size_t>(v)]) {
    case Star::Convex:
      return any_front ? -1 : 1;
    case Star::Concave:
      return all_front ? -1 : 1;
    case Star::Saddle:
      return 0;
  }
  return 0;
}

SegmentVerdict SegmentFilter::classify(int i, int j) const {
  if (!usable_) return SegmentVerdict::Unsure;
  const double p[3] = {surface_.V(i, 0), surface_.V(i, 1), surface_.V(i, 2)};
  const double q[3] = {surface_.V(j, 0), surface_.V(j, 1), surface_.V(j, 2)};
  bool unsure = false;
  std::optional<SegmentVerdict> decided;
  for_each_face_along(Segment(p, q), [&](const Face& face) {
    const bool at_i = has_vertex(face.v, i), at_j = has_vertex(face.v, j);
    if (at_i && at_j) {  // the fiber is an edge, on the surface
      decided = SegmentVerdict::Inside;
      return false;
    }
    if (at_i || at_j) return true;  // decided with the stars below
    const int sp = certified_orientation(face.a, face.b, face.c, p);
    const int sq = certified_orientation(face.a, face.b, face.c, q);
    if (sp != 0 && sp == sq) return true;  // both ends on one side of the face's plane
    const LineAtTriangle line = line_at_triangle(certified_orientation(p, q, face.a, face.b),
                                                 certified_orientation(p, q, face.b, face.c),
                                                 certified_orientation(p, q, face.c, face.a));
    if (line == LineAtTriangle::Beside) return true;
    if (line == LineAtTriangle::Through && sp != 0 && sq != 0) {
      decided = SegmentVerdict::Crosses;  // wherever else it touches, part of it is outside
      return false;
    }
    unsure = true;
    return true;
  });
  if (decided) return *decided;
  if (unsure) return SegmentVerdict::Unsure;
  // The faces at either end meet the segment only there, unless the other
  // end is in their plane; the star tests certify that too.
  const int from_i = starts_inside(i, q);
  const int from_j = starts_inside(j, p);
  if (from_i == 2 || from_j == 2) return SegmentVerdict::Unsure;
  if (from_i != 0) return from_i > 0 ? SegmentVerdict::Inside : SegmentVerdict::Outside;
  if (from_j != 0) return from_j > 0 ? SegmentVerdict::Inside : SegmentVerdict::Outside;
  const int inside = midpoint_inside(p, q);
  return inside > 0   ? SegmentVerdict::Inside
         : inside < 0 ? SegmentVerdict::Outside
                      : SegmentVerdict::Clear;
}

int SegmentFilter::midpoint_inside(const double* p, const double* q) const {
  // Directions off the axes and the mesh's symmetry planes, so that a ray
  // rarely grazes an edge of a generated mesh.
  static constexpr double kDirections[4][3] = {{0.5377, 0.8012, -0.2618},
                                               {-0.7071, 0.3162, 0.6325},
                                               {0.1961, -0.4472, 0.8729},
                                               {-0.3015, -0.9045, -0.3015}};
  for (const auto& direction : kDirections) {
    const int parity = ray_parity(p, q, direction);
    if (parity >= 0) return parity == 1 ? 1 : -1;
  }
  return 0;
}

int SegmentFilter::ray_parity(const double* p, const double* q, const double* direction) const {
  // The rounded midpoint only places the ray's far end and culls boxes (the
  // margin covers its rounding); every sign is taken at the exact midpoint,
  // as the mean of the signed volumes at p and at q (they are affine in it).
  const double m[3] = {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])};
  const double far[3] = {m[0] + reach_ * direction[0], m[1] + reach_ * direction[1],
                         m[2] + reach_ * direction[2]};
  // orientation(m, x, y, z): the ray's line against the edge yz when x is far.
  auto volume_from_midpoint = [&](const double* x, const double* y, const double* z) {
    double dp, bp, dq, bq;
    orientation_with_bound(p, x, y, z, dp, bp);
    orientation_with_bound(q, x, y, z, dq, bq);
    return certified_mean_sign(dp, bp, dq, bq);
  };
  // orientation(a, b, c, m): the midpoint's side of a face's plane.
  auto midpoint_side = [&](const double* a, const double* b, const double* c) {
    double dp, bp, dq, bq;
    orientation_with_bound(a, b, c, p, dp, bp);
    orientation_with_bound(a, b, c, q, dq, bq);
    return certified_mean_sign(dp, bp, dq, bq);
  };
  int crossings = 0;
  const bool certain = for_each_face_along(Segment(m, far), [&](const Face& face) {
    const LineAtTriangle line = line_at_triangle(volume_from_midpoint(far, face.a, face.b),
                                                 volume_from_midpoint(far, face.b, face.c),
                                                 volume_from_midpoint(far, face.c, face.a));
    if (line == LineAtTriangle::Beside) return true;
    if (line == LineAtTriangle::Unsure) return false;  // near an edge or a corner
    const int side_m = midpoint_side(face.a, face.b, face.c);
    const int side_far = certified_orientation(face.a, face.b, face.c, far);
    if (side_m == 0 || side_far == 0) return false;
    if (side_m != side_far) ++crossings;
    return true;
  });
  return certain ? crossings % 2 : -1;
}

}  // namespace fiberfluid::geom
