// SPDX-License-Identifier: GPL-3.0-or-later
// The float pre-filter of the exact pruning: decides most fibers in plain
// doubles with certified signs (certified_sign.hpp) and a bounding-volume
// hierarchy over the faces, and hands every case it cannot certify (a
// touch, a graze, a fiber along an edge, coordinates out of range) to the
// exact CGAL path in fiber_pruning.cpp. It never decides a fiber the exact
// path would decide otherwise.
#pragma once

#include <cstdint>
#include <vector>

#include "fiberfluid/geom/surface.hpp"

namespace fiberfluid::geom {

// The shape of the solid at a vertex, from its incident faces (decided
// exactly by the caller): a convex cone, the complement of one, or a saddle.
enum class Star : uint8_t { Convex, Concave, Saddle };

enum class SegmentVerdict : uint8_t {
  Crosses,  // properly crosses a face's interior: pruned
  Inside,   // meets the surface only at its ends and starts into the solid
  Outside,  // meets the surface only at its ends and starts out of it
  Clear,    // meets the surface only at its ends, on a side nothing certified
  Unsure,   // a contact or a sign the doubles cannot certify: decide exactly
};

class SegmentFilter {
 public:
  // stars: one per vertex of the 3D surface.
  SegmentFilter(const Surface& surface, std::vector<Star> stars);

  // The fiber between vertices i and j.
  SegmentVerdict classify(int i, int j) const;

 private:
  struct Node {
    double lo[3], hi[3];
    int begin, end;  // faces [begin, end) in leaf order; empty for inner nodes
    int skip;        // the node after this one's subtree
  };
  struct Face {
    double a[3], b[3], c[3];
    int v[3];
  };

  // A segment prepared for slab tests against many boxes.
  struct Segment {
    Segment(const double* from, const double* to);
    double start[3], inverse[3];
    bool parallel[3];
  };

  void build(std::vector<int>& order, const std::vector<Face>& faces, int begin, int end);
  bool crosses_box(const Node& node, const Segment& segment) const;
  // visit(face) for each face whose box the segment crosses, until it
  // returns false; false when it did.
  template <class Visit>
  bool for_each_face_along(const Segment& segment, Visit&& visit) const;
  // Where the star of v decides a segment from v towards x that meets no face
  // but at v: +1 inside, -1 outside, 0 undecided; 2 when a sign is unsure.
  int starts_inside(int v, const double* x) const;
  // Whether the open segment pq, which meets no face, lies inside: the parity
  // of the faces that a ray from its midpoint crosses. +1, -1, or 0 when no
  // direction tried certifies every sign it needs.
  int midpoint_inside(const double* p, const double* q) const;
  // The parity of one ray's crossings (0 or 1), or -1 when a sign is unsure.
  int ray_parity(const double* p, const double* q, const double* direction) const;

  const Surface& surface_;
  std::vector<Star> stars_;
  std::vector<Face> faces_;                 // leaf order
  std::vector<std::vector<int>> incident_;  // each vertex's faces, as positions in faces_
  std::vector<Node> nodes_;
  double reach_ = 0.0;   // a ray's length that leaves every box
  double margin_ = 0.0;  // box inflation covering the slab test's rounding
  bool usable_ = true;   // coordinates within the certified range
};

}  // namespace fiberfluid::geom
