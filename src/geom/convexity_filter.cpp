// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/convexity_filter.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

#include "fiberfluid/geom/certified_sign.hpp"
#include "fiberfluid/util/progress.hpp"
#include "fiberfluid/util/run_control.hpp"

namespace fiberfluid::geom {

namespace {

constexpr int kClusterVertices = 64;

struct Cluster {
  double lo[3], hi[3];
  std::vector<int> vertices;
};

// Leaves of a median split of the vertices: compact boxes to cull by.
void split(const Surface& s, std::vector<int>::iterator begin, std::vector<int>::iterator end,
           std::vector<Cluster>& clusters) {
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (auto v = begin; v != end; ++v)
    for (int x = 0; x < 3; ++x) {
      lo[x] = std::min(lo[x], s.V(*v, x));
      hi[x] = std::max(hi[x], s.V(*v, x));
    }
  if (end - begin <= kClusterVertices) {
    clusters.push_back(Cluster{{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}, {begin, end}});
    return;
  }
  int axis = 0;
  for (int x = 1; x < 3; ++x)
    if (hi[x] - lo[x] > hi[axis] - lo[axis]) axis = x;
  const auto middle = begin + (end - begin) / 2;
  std::nth_element(begin, middle, end, [&](int a, int b) { return s.V(a, axis) < s.V(b, axis); });
  split(s, begin, middle, clusters);
  split(s, middle, end, clusters);
}

// A face's plane in doubles: its point a, the float normal (b - a) x (c - a)
// and, per component, the permanent that bounds the normal's rounding.
struct FacePlane {
  const double* a;
  double normal[3], permanent[3];

  FacePlane(const double* a_, const double* b, const double* c) : a(a_) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    for (int k = 0; k < 3; ++k) {
      const int y = (k + 1) % 3, z = (k + 2) % 3;
      normal[k] = u[y] * v[z] - u[z] * v[y];
      permanent[k] = std::abs(u[y] * v[z]) + std::abs(u[z] * v[y]);
    }
  }

  // True when every point of the box is certainly behind the plane: the
  // float normal's support point over the box, plus bounds on the normal's
  // rounding and on the evaluation's.
  bool box_behind(const Cluster& box) const {
    double support = 0.0, error = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double corner = normal[k] > 0.0 ? box.hi[k] : box.lo[k];
      support += normal[k] * (corner - a[k]);
      const double reach = std::max(std::abs(box.lo[k] - a[k]), std::abs(box.hi[k] - a[k]));
      error += (std::abs(normal[k]) + permanent[k]) * reach;
    }
    return support + 16.0 * 0x1p-53 * error < 0.0;
  }
};

}  // namespace

std::optional<ConvexityScreen> screen_convexity(const Surface& s) {
  for (int i = 0; i < s.num_vertices(); ++i)
    for (int x = 0; x < 3; ++x)
      if (!coordinate_in_filter_range(s.V(i, x))) return std::nullopt;
  std::vector<int> order(static_cast<size_t>(s.num_vertices()));
  std::iota(order.begin(), order.end(), 0);
  std::vector<Cluster> clusters;
  split(s, order.begin(), order.end(), clusters);
  // Row-major copies: the vertex loop reads three contiguous doubles.
  std::vector<double> xyz(3 * static_cast<size_t>(s.num_vertices()));
  for (int i = 0; i < s.num_vertices(); ++i)
    for (int x = 0; x < 3; ++x) xyz[3 * static_cast<size_t>(i) + x] = s.V(i, x);
  auto point = [&](int i) { return xyz.data() + 3 * static_cast<size_t>(i); };

  ConvexityScreen screen;
  std::atomic<bool> in_front{false};
  std::atomic<long long> faces_done{0};
  const double faces = s.num_faces();
#pragma omp parallel
  {
    std::vector<std::pair<int, int>> unsure;
#pragma omp for schedule(dynamic, 64)
    for (int f = 0; f < s.num_faces(); ++f) {
      if (in_front.load(std::memory_order_relaxed) || cancel_requested()) continue;
      const double *a = point(s.F(f, 0)), *b = point(s.F(f, 1)), *c = point(s.F(f, 2));
      const FacePlane plane(a, b, c);  // once per face, for every cluster
      for (const Cluster& cluster : clusters) {
        if (plane.box_behind(cluster)) continue;
        for (int v : cluster.vertices) {
          if (v == s.F(f, 0) || v == s.F(f, 1) || v == s.F(f, 2)) continue;  // in its plane
          const int sign = certified_orientation(a, b, c, point(v));
          if (sign > 0) in_front = true;
          if (sign == 0) unsure.emplace_back(f, v);
        }
      }
      const long long done = ++faces_done;
      if (done % 4096 == 0 && omp_get_thread_num() == 0)
        report_progress("convexity check", static_cast<double>(done), faces);
    }
#pragma omp critical
    screen.unsure.insert(screen.unsure.end(), unsure.begin(), unsure.end());
  }
  throw_if_cancelled("the convexity check");
  screen.vertex_in_front = in_front;
  // The same list whatever the threads did: the exact pass reads it in order.
  std::sort(screen.unsure.begin(), screen.unsure.end());
  return screen;
}

}  // namespace fiberfluid::geom
