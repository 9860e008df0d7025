// SPDX-License-Identifier: GPL-3.0-or-later
// Exact pruning of the fibers that leave a concave body (model.md section 3;
// the method paper's "Concave objects"). CGAL stays in this file.
#include "fiberfluid/geom/fiber_pruning.hpp"

#include <omp.h>

#include <atomic>

#include "fiberfluid/geom/convexity_filter.hpp"
#include "fiberfluid/geom/segment_filter.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <chrono>
#include <numeric>
#include <optional>

namespace fiberfluid::geom {

namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;

// ------------------------------------------------------------------ 3D
using Triangle = Epick::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Epick, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Epick, Primitive>>;
using ExactMesh = CGAL::Surface_mesh<Epeck::Point_3>;
using ExactSide = CGAL::Side_of_triangle_mesh<ExactMesh, Epeck>;

Epick::Point_3 point3(const Eigen::MatrixXd& V, int i) { return {V(i, 0), V(i, 1), V(i, 2)}; }
Epeck::Point_3 exact_point(const Eigen::MatrixXd& V, int i) { return {V(i, 0), V(i, 1), V(i, 2)}; }

// Everything one thread needs to classify pieces of segments exactly. Each
// thread builds its own, so no exact (lazy) number is shared across threads.
struct ExactSolid {
  ExactMesh mesh;
  std::vector<Epeck::Triangle_3> triangles;
  std::unique_ptr<ExactSide> side;

  explicit ExactSolid(const Surface& s) {
    std::vector<ExactMesh::Vertex_index> vertex;
    for (int i = 0; i < s.num_vertices(); ++i)
      vertex.push_back(mesh.add_vertex(exact_point(s.V, i)));
    for (int f = 0; f < s.num_faces(); ++f) {
      mesh.add_face(vertex[static_cast<size_t>(s.F(f, 0))], vertex[static_cast<size_t>(s.F(f, 1))],
                    vertex[static_cast<size_t>(s.F(f, 2))]);
      triangles.emplace_back(mesh.point(vertex[static_cast<size_t>(s.F(f, 0))]),
                             mesh.point(vertex[static_cast<size_t>(s.F(f, 1))]),
                             mesh.point(vertex[static_cast<size_t>(s.F(f, 2))]));
    }
    side = std::make_unique<ExactSide>(mesh);
  }

  bool outside(const Epeck::Point_3& p) const { return (*side)(p) == CGAL::ON_UNBOUNDED_SIDE; }

  // The general case: the parameters t in [0, 1] where the segment meets the
  // faces split it into open pieces; a piece on the surface is kept, any
  // other piece is wholly inside or outside, decided at its midpoint.
  bool segment_inside(const Epeck::Point_3& p, const Epeck::Point_3& q,
                      const std::vector<int>& faces) const {
    const Epeck::Segment_3 segment(p, q);
    const Epeck::Vector_3 d = q - p;
    const Epeck::FT dd = d * d;
    auto parameter = [&](const Epeck::Point_3& x) { return ((x - p) * d) / dd; };
    std::vector<Epeck::FT> breaks = {0, 1};
    std::vector<std::pair<Epeck::FT, Epeck::FT>> on_surface;
    for (int f : faces) {
      const auto hit = CGAL::intersection(segment, triangles[static_cast<size_t>(f)]);
      if (!hit) continue;
      if (const auto* point = boost::get<Epeck::Point_3>(&*hit)) {
        breaks.push_back(parameter(*point));
      } else if (const auto* piece = boost::get<Epeck::Segment_3>(&*hit)) {
        Epeck::FT a = parameter(piece->source()), b = parameter(piece->target());
        if (b < a) std::swap(a, b);
        breaks.push_back(a);
        breaks.push_back(b);
        on_surface.emplace_back(a, b);
      }
    }
    std::sort(breaks.begin(), breaks.end());
    breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
    for (size_t k = 0; k + 1 < breaks.size(); ++k) {
      const Epeck::FT& a = breaks[k];
      const Epeck::FT& b = breaks[k + 1];
      const bool covered = std::any_of(on_surface.begin(), on_surface.end(), [&](const auto& s) {
        return s.first <= a && b <= s.second;
      });
      if (!covered && outside(p + ((a + b) / 2) * d)) return false;
    }
    return true;
  }
};

// The shape of the solid at a vertex (Star, segment_filter.hpp), from its
// incident faces: a convex cone (no ring vertex in front of an incident
// face's plane), the complement of one (none behind), or a saddle.
struct VertexStars {
  std::vector<Star> star;
  std::vector<std::vector<int>> faces;  // incident faces per vertex

  explicit VertexStars(const Surface& s)
      : star(static_cast<size_t>(s.num_vertices())), faces(static_cast<size_t>(s.num_vertices())) {
    for (int f = 0; f < s.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) faces[static_cast<size_t>(s.F(f, k))].push_back(f);
    for (int v = 0; v < s.num_vertices(); ++v) {
      bool front = false, behind = false;
      for (int f : faces[static_cast<size_t>(v)])
        for (int g : faces[static_cast<size_t>(v)])
          for (int k = 0; k < 3; ++k) {
            const CGAL::Orientation o =
                CGAL::orientation(point3(s.V, s.F(f, 0)), point3(s.V, s.F(f, 1)),
                                  point3(s.V, s.F(f, 2)), point3(s.V, s.F(g, k)));
            front |= o == CGAL::POSITIVE;
            behind |= o == CGAL::NEGATIVE;
          }
      star[static_cast<size_t>(v)] = !front ? Star::Convex : !behind ? Star::Concave : Star::Saddle;
    }
  }

  // Whether the segment from vertex v towards q starts into the solid, when
  // the star of v decides it with orientation tests alone; nothing otherwise.
  std::optional<bool> starts_inside(const Surface& s, int v, const Epick::Point_3& q) const {
    const Star kind = star[static_cast<size_t>(v)];
    if (kind == Star::Saddle) return std::nullopt;
    bool any_front = false, all_front = true;
    for (int f : faces[static_cast<size_t>(v)]) {
      const CGAL::Orientation o = CGAL::orientation(point3(s.V, s.F(f, 0)), point3(s.V, s.F(f, 1)),
                                                    point3(s.V, s.F(f, 2)), q);
      if (o == CGAL::COPLANAR) return std::nullopt;
      any_front |= o == CGAL::POSITIVE;
      all_front &= o == CGAL::POSITIVE;
    }
    // A convex cone is the intersection of the face half-spaces; a concave
    // star's outside is the intersection of the opposite ones.
    return kind == Star::Convex ? !any_front : !all_front;
  }
};

bool incident(const Eigen::MatrixXi& F, int f, int v) {
  return F(f, 0) == v || F(f, 1) == v || F(f, 2) == v;
}

// Decides one fiber. Exact predicates settle the usual cases: a proper
// crossing of a face's interior prunes; no contact at all leaves the whole
// open segment inside or outside, decided at its midpoint. Any other
// contact goes to the exact piecewise test.
// first: the start of the triangles the tree was built on (face f at first + f).
bool keep_fiber(const Surface& s, const Tree& tree, TriangleIterator first,
                const VertexStars& stars, const ExactSolid& exact, int i, int j,
                std::vector<int>& faces, long long& fallbacks) {
  const Epick::Point_3 p = point3(s.V, i), q = point3(s.V, j);
  faces.clear();
  std::vector<Tree::Primitive_id> hits;
  tree.all_intersected_primitives(Epick::Segment_3(p, q), std::back_inserter(hits));
  bool degenerate = false;
  for (const Tree::Primitive_id& id : hits) {
    const int f = static_cast<int>(id - first);
    faces.push_back(f);
    const Triangle& t = *id;
    const bool at_i = incident(s.F, f, i), at_j = incident(s.F, f, j);
    if (at_i && at_j) {  // ij is an edge of this face: the fiber runs on the surface there
      degenerate = true;
      continue;
    }
    if (at_i || at_j) {
      // A face at one end meets the segment only there, unless coplanar.
      const Epick::Point_3& other = at_i ? q : p;
      if (CGAL::orientation(t[0], t[1], t[2], other) == CGAL::COPLANAR) degenerate = true;
      continue;
    }
    const CGAL::Orientation op = CGAL::orientation(t[0], t[1], t[2], p);
    const CGAL::Orientation oq = CGAL::orientation(t[0], t[1], t[2], q);
    if (op != CGAL::COPLANAR && oq != CGAL::COPLANAR && op != oq) {
      const CGAL::Orientation e0 = CGAL::orientation(p, q, t[0], t[1]);
      const CGAL::Orientation e1 = CGAL::orientation(p, q, t[1], t[2]);
      const CGAL::Orientation e2 = CGAL::orientation(p, q, t[2], t[0]);
      if (e0 != CGAL::COPLANAR && e0 == e1 && e1 == e2) return false;  // crosses a face's interior
    }
    degenerate = true;  // through an edge or a vertex, or in the face's plane
  }
  if (!degenerate) {
    // The open segment meets the surface nowhere: it is wholly inside or
    // outside, as it starts at either end.
    if (const auto inside = stars.starts_inside(s, i, q)) return *inside;
    if (const auto inside = stars.starts_inside(s, j, p)) return *inside;
  }
  const Epeck::Point_3 pe = exact_point(s.V, i), qe = exact_point(s.V, j);
  if (!degenerate) return !exact.outside(CGAL::midpoint(pe, qe));
  ++fallbacks;
  return exact.segment_inside(pe, qe, faces);
}

// body(j) for each partner j > i to test: the candidates' kept ones, or all.
template <class Body>
void for_each_later_partner(const FiberMask* candidates, int i, int n, Body&& body) {
  if (candidates == nullptr) {
    for (int j = i + 1; j < n; ++j) body(j);
    return;
  }
  candidates->for_each_kept(i, [&](int j) {
    if (j > i) body(j);
  });
}

// The pairs to test: the candidates' kept ones, or all N (N - 1) / 2.
double pairs_to_test(const FiberMask* candidates, int n) {
  return candidates ? static_cast<double>(candidates->num_kept()) : 0.5 * n * (n - 1.0);
}

// The mask the pruning starts from: the candidates, or every pair.
FiberMask starting_mask(const FiberMask* candidates, int n) {
  return candidates ? *candidates : FiberMask(n);
}

PruningResult prune_3d(const Surface& s, const FiberMask* candidates) {
  PruningResult result{starting_mask(candidates, s.num_vertices())};
  std::vector<Triangle> triangles;
  for (int f = 0; f < s.num_faces(); ++f)
    triangles.emplace_back(point3(s.V, s.F(f, 0)), point3(s.V, s.F(f, 1)), point3(s.V, s.F(f, 2)));
  const Tree tree(triangles.cbegin(), triangles.cend());
  const VertexStars stars(s);
  const SegmentFilter filter(s, stars.star);
  const int n = s.num_vertices();
  long long fallbacks = 0, clear = 0, filtered = 0;
  const double pairs = pairs_to_test(candidates, n);
  std::atomic<long long> pairs_done{0};
  report_progress("pruning", 0.0, pairs);
  ThreadFailure failure;
  // Pruned pairs are gathered per thread and applied after the loop: a
  // sparse mask's lists may not be edited from two threads.
  std::vector<std::vector<std::pair<int, int>>> pruned(static_cast<size_t>(omp_get_max_threads()));
#pragma omp parallel reduction(+ : fallbacks, clear, filtered)
  {
    std::vector<std::pair<int, int>>& mine = pruned[static_cast<size_t>(omp_get_thread_num())];
    // Every thread reaches the loop (its barrier waits for all), failed or not.
    std::optional<ExactSolid> solid;
    try {
      solid.emplace(s);
    } catch (...) {
      failure.capture();
    }
    std::vector<int> faces;
#pragma omp for schedule(dynamic, 4)
    for (int i = 0; i < n; ++i) {
      // No break out of an OpenMP loop: the rest is skipped.
      if (cancel_requested() || failure.happened() || !solid) continue;
      const ExactSolid& exact = *solid;
      long long tested = 0;
      try {
        for_each_later_partner(candidates, i, n, [&](int j) {
          ++tested;
          bool keep = true;
          const SegmentVerdict verdict = filter.classify(i, j);
          filtered += verdict != SegmentVerdict::Clear && verdict != SegmentVerdict::Unsure;
          switch (verdict) {
            case SegmentVerdict::Crosses:
            case SegmentVerdict::Outside:
              keep = false;
              break;
            case SegmentVerdict::Inside:
              break;
            case SegmentVerdict::Clear:  // the open segment is wholly inside or outside
              ++clear;
              keep = !exact.outside(CGAL::midpoint(exact_point(s.V, i), exact_point(s.V, j)));
              break;
            case SegmentVerdict::Unsure:
              keep = keep_fiber(s, tree, triangles.cbegin(), stars, exact, i, j, faces, fallbacks);
              break;
          }
          if (!keep) mine.emplace_back(i, j);
        });
      } catch (...) {
        failure.capture();
      }
      const long long done = pairs_done += tested;
      if (omp_get_thread_num() == 0) report_progress("pruning", static_cast<double>(done), pairs);
    }
  }
  failure.rethrow_if_any();
  throw_if_cancelled("the fiber pruning");
  for (const auto& list : pruned)
    for (const auto& [i, j] : list) result.mask.prune(i, j);
  report_progress("pruning", pairs, pairs);
  result.exact_fallbacks = fallbacks + clear;
  result.decided_in_doubles = filtered;
  return result;
}

// ------------------------------------------------------------------ 2D
using ExactPoint2 = Epeck::Point_2;

// A closed polygon: brute force over its edges (2D outlines are small).
PruningResult prune_2d(const Surface& s, const FiberMask* candidates) {
  PruningResult result{starting_mask(candidates, s.num_vertices())};
  const int n = s.num_vertices();
  std::vector<ExactPoint2> exact(static_cast<size_t>(n));
  std::vector<Epick::Point_2> point(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    exact[static_cast<size_t>(i)] = ExactPoint2(s.V(i, 0), s.V(i, 1));
    point[static_cast<size_t>(i)] = Epick::Point_2(s.V(i, 0), s.V(i, 1));
  }
  // The outline in order, for the point-in-polygon test.
  std::vector<ExactPoint2> outline;
  {
    std::vector<int> next(static_cast<size_t>(n), -1);
    for (int f = 0; f < s.num_faces(); ++f) next[static_cast<size_t>(s.F(f, 0))] = s.F(f, 1);
    int at = s.F(0, 0);
    for (int k = 0; k < s.num_faces(); ++k) {
      outline.push_back(exact[static_cast<size_t>(at)]);
      at = next[static_cast<size_t>(at)];
    }
  }
  auto outside = [&](const ExactPoint2& x) {
    return CGAL::bounded_side_2(outline.begin(), outline.end(), x, Epeck()) ==
           CGAL::ON_UNBOUNDED_SIDE;
  };
  long long fallbacks = 0;
  std::vector<std::pair<int, int>> pruned;  // applied after the loop, as in 3D
  for (int i = 0; i < n; ++i) {
    throw_if_cancelled("the fiber pruning");
    for_each_later_partner(candidates, i, n, [&](int j) {
      const Epick::Point_2 &p = point[static_cast<size_t>(i)], &q = point[static_cast<size_t>(j)];
      bool degenerate = false, crossed = false;
      for (int f = 0; f < s.num_faces() && !crossed; ++f) {
        const int a = s.F(f, 0), b = s.F(f, 1);
        const Epick::Point_2 &u = point[static_cast<size_t>(a)], &v = point[static_cast<size_t>(b)];
        const bool at_i = a == i || b == i, at_j = a == j || b == j;
        if (at_i && at_j) {
          degenerate = true;
          continue;
        }  // ij is an edge
        if (at_i || at_j) {
          if (CGAL::orientation(u, v, at_i ? q : p) == CGAL::COLLINEAR) degenerate = true;
          continue;
        }
        const CGAL::Orientation op = CGAL::orientation(u, v, p), oq = CGAL::orientation(u, v, q);
        const CGAL::Orientation ou = CGAL::orientation(p, q, u), ov = CGAL::orientation(p, q, v);
        if (op != CGAL::COLLINEAR && oq != CGAL::COLLINEAR && op != oq && ou != CGAL::COLLINEAR &&
            ov != CGAL::COLLINEAR && ou != ov)
          crossed = true;  // a proper crossing of an edge's interior
        else if (CGAL::do_intersect(Epick::Segment_2(p, q), Epick::Segment_2(u, v)))
          degenerate = true;
      }
      bool keep = !crossed;
      if (keep && !degenerate) {
        keep =
            !outside(CGAL::midpoint(exact[static_cast<size_t>(i)], exact[static_cast<size_t>(j)]));
      } else if (keep) {
        ++fallbacks;
        // Split at every contact with the outline; classify each open piece.
        const ExactPoint2 &pe = exact[static_cast<size_t>(i)], &qe = exact[static_cast<size_t>(j)];
        const Epeck::Vector_2 d = qe - pe;
        const Epeck::FT dd = d * d;
        std::vector<Epeck::FT> breaks = {0, 1};
        std::vector<std::pair<Epeck::FT, Epeck::FT>> on_surface;
        const Epeck::Segment_2 segment(pe, qe);
        for (int f = 0; f < s.num_faces(); ++f) {
          const auto hit =
              CGAL::intersection(segment, Epeck::Segment_2(exact[static_cast<size_t>(s.F(f, 0))],
                                                           exact[static_cast<size_t>(s.F(f, 1))]));
          if (!hit) continue;
          if (const auto* x = boost::get<ExactPoint2>(&*hit)) {
            breaks.push_back(((*x - pe) * d) / dd);
          } else if (const auto* piece = boost::get<Epeck::Segment_2>(&*hit)) {
            Epeck::FT a = ((piece->source() - pe) * d) / dd, b = ((piece->target() - pe) * d) / dd;
            if (b < a) std::swap(a, b);
            breaks.insert(breaks.end(), {a, b});
            on_surface.emplace_back(a, b);
          }
        }
        std::sort(breaks.begin(), breaks.end());
        breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
        for (size_t k = 0; keep && k + 1 < breaks.size(); ++k) {
          const bool covered =
              std::any_of(on_surface.begin(), on_surface.end(), [&](const auto& piece) {
                return piece.first <= breaks[k] && breaks[k + 1] <= piece.second;
              });
          if (!covered && outside(pe + ((breaks[k] + breaks[k + 1]) / 2) * d)) keep = false;
        }
      }
      if (!keep) pruned.emplace_back(i, j);
    });
  }
  for (const auto& [i, j] : pruned) result.mask.prune(i, j);
  result.exact_fallbacks = fallbacks;
  return result;
}

}  // namespace

bool is_convex(const Surface& s) {
  if (s.dim == 3) {
    if (const std::optional<ConvexityScreen> screen = screen_convexity(s)) {
      if (screen->vertex_in_front) return false;
      return std::none_of(screen->unsure.begin(), screen->unsure.end(), [&](const auto& pair) {
        const auto [f, v] = pair;
        return CGAL::orientation(point3(s.V, s.F(f, 0)), point3(s.V, s.F(f, 1)),
                                 point3(s.V, s.F(f, 2)), point3(s.V, v)) == CGAL::POSITIVE;
      });
    }
  }
  // 2D outlines, and coordinates beyond the float filter's range: every
  // vertex against every face with CGAL's predicates.
  const double faces = s.num_faces();
  for (int f = 0; f < s.num_faces(); ++f) {
    if (f % 1024 == 0) {
      throw_if_cancelled("the convexity check");
      report_progress("convexity check", f, faces);
    }
    for (int v = 0; v < s.num_vertices(); ++v) {
      if (s.dim == 3) {
        const CGAL::Orientation o = CGAL::orientation(
            point3(s.V, s.F(f, 0)), point3(s.V, s.F(f, 1)), point3(s.V, s.F(f, 2)), point3(s.V, v));
        // Outward faces: POSITIVE is in front of the plane, outside the body.
        if (o == CGAL::POSITIVE) return false;
      } else {
        const CGAL::Orientation o =
            CGAL::orientation(Epick::Point_2(s.V(s.F(f, 0), 0), s.V(s.F(f, 0), 1)),
                              Epick::Point_2(s.V(s.F(f, 1), 0), s.V(s.F(f, 1), 1)),
                              Epick::Point_2(s.V(v, 0), s.V(v, 1)));
        if (o == CGAL::RIGHT_TURN) return false;  // right of a CCW edge: outside
      }
    }
  }
  report_progress("convexity check", faces, faces);
  return true;
}

PruningResult prune_fibers(const Surface& surface, bool convex_fast_path,
                           const FiberMask* candidates) {
  const auto start = std::chrono::steady_clock::now();
  PruningResult result{starting_mask(candidates, surface.num_vertices())};
  if (convex_fast_path && is_convex(surface)) {
    result.convex = true;
  } else {
    result = surface.dim == 3 ? prune_3d(surface, candidates) : prune_2d(surface, candidates);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace fiberfluid::geom
