// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/mirror_layer.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "fiberfluid/geom/surface.hpp"
#include "fiberfluid/model/fiber_network.hpp"
#include "fiberfluid/model/held_edge.hpp"
#include "fiberfluid/model/pair_stencil.hpp"
#include "fiberfluid/model/point_fibers.hpp"

namespace fiberfluid::model {

namespace {

std::string metres(double value) {
  std::ostringstream out;
  out.precision(3);
  out << value << " m";
  return out.str();
}

}  // namespace

Status find_clamp_plane(const Eigen::MatrixXd& reference, const std::vector<int>& held,
                        MirrorLayer* layer) {
  if (held.empty()) return Status::failure("it holds no vertex");
  const int dim = static_cast<int>(reference.cols());
  const double tolerance = 1e-6 * geom::bounding_box_diagonal(reference);
  Eigen::MatrixXd points(static_cast<Eigen::Index>(held.size()), dim);
  for (size_t k = 0; k < held.size(); ++k)
    points.row(static_cast<Eigen::Index>(k)) = reference.row(held[k]);
  const Eigen::RowVectorXd centre = points.colwise().mean();
  const Eigen::MatrixXd centred = points.rowwise() - centre;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullV);
  // A plane (3D) needs two spreading directions, a line (2D) one.
  const Eigen::VectorXd spread = svd.singularValues();
  if (spread.size() < dim - 1 || spread[dim - 2] <= tolerance * std::sqrt(double(held.size())))
    return Status::failure(std::string("its vertices do not span a ") +
                           (dim == 3 ? "plane" : "line"));
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal.head(dim) = svd.matrixV().col(dim - 1);
  const double off = (centred * normal.head(dim)).cwiseAbs().maxCoeff();
  if (off > tolerance)
    return Status::failure(std::string("its vertices are not on one ") +
                           (dim == 3 ? "plane" : "line") + " (one is " + metres(off) +
                           " off their best one)");
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  point.head(dim) = centre.transpose();
  const Eigen::VectorXd side = (reference.rowwise() - centre) * normal.head(dim);
  const double above = side.maxCoeff(), below = -side.minCoeff();
  if (above > tolerance && below > tolerance)
    return Status::failure("the body lies on both sides of its plane (" + metres(above) + " and " +
                           metres(below) +
                           " away): a mirror layer needs the clamp on the body's boundary");
  if (std::max(above, below) <= tolerance)
    return Status::failure("the whole body lies on its plane");
  layer->point = point;
  layer->normal = above > below ? normal : Eigen::Vector3d(-normal);
  layer->held = held;
  return {};
}

namespace {

// Two layers on one plane (the halves of one clamp, given as two groups).
bool same_plane(const MirrorLayer& a, const MirrorLayer& b, double tolerance) {
  return a.normal.dot(b.normal) > 1.0 - 1e-9 &&
         std::abs((b.point - a.point).dot(a.normal)) <= tolerance;
}

// The same layer, whether `layer` is the model's own entry or a copy of it.
bool same_layer(const MirrorLayer& a, const MirrorLayer& b) {
  return a.group == b.group && a.held == b.held && a.point == b.point && a.normal == b.normal;
}

// Where a layer's fibers may cross its plane: within `reach` of a vertex its
// group holds, and nearer to one of those than to any vertex that another
// layer on the same plane holds (a layer made by hand without its held
// vertices acts across the whole plane). A clamp on part of a face acts across that
// part only, and the two halves of one clamp, each with its layer, make one
// layer between them, not two on top of each other (issue 43).
class ClampedRegion {
 public:
  ClampedRegion(const Model& model, const MirrorLayer& layer) {
    const Eigen::MatrixXd& V = model.surface.V;
    const double tolerance = 1e-6 * geom::bounding_box_diagonal(V);
    std::vector<char> own(static_cast<size_t>(model.num_vertices()), 0);
    for (int v : layer.held) own[static_cast<size_t>(v)] = 1;
    for (const MirrorLayer& other : model.mirror_layers)
      if (same_plane(layer, other, tolerance))
        for (int v : other.held) {
          if (!same_layer(other, layer) && own[static_cast<size_t>(v)]) continue;  // shared: ours
          points_.push_back(padded_row(V, v));
          ours_.push_back(same_layer(other, layer) || own[static_cast<size_t>(v)]);
        }
    // The mesh's resolution on the clamp: its longest edge between two held vertices.
    const Eigen::MatrixXi& F = model.surface.F;
    for (Eigen::Index f = 0; f < F.rows(); ++f)
      for (Eigen::Index a = 0; a < F.cols(); ++a) {
        const int u = F(f, a), w = F(f, (a + 1) % F.cols());
        if (own[static_cast<size_t>(u)] && own[static_cast<size_t>(w)])
          reach_ = std::max(reach_, (V.row(u) - V.row(w)).norm());
      }
  }
  bool holds(const Eigen::Vector3d& crossing) const {
    if (points_.empty()) return true;  // a layer made without its held vertices: the whole plane
    double nearest = std::numeric_limits<double>::infinity();
    bool ours = false;
    for (size_t k = 0; k < points_.size(); ++k) {
      const double d = (points_[k] - crossing).squaredNorm();
      if (d < nearest) nearest = d, ours = ours_[k];
    }
    return ours && nearest <= reach_ * reach_;
  }

 private:
  std::vector<Eigen::Vector3d> points_;
  std::vector<char> ours_;
  double reach_ = 0.0;
};

}  // namespace

namespace {

// The bulk weight of a pair (i, j) at a layer fiber's length L (the fiber
// from s_i to an image of s_j): its influence and counts as a bulk fiber's.
double layer_pair_weight(const Model& model, const PairFactors& factors,
                         const std::vector<double>& counts, const Eigen::VectorXd& area0, int i,
                         int j, double length) {
  return counted_bulk_weight(model.influence(length), area0[i], area0[j],
                             counts[static_cast<size_t>(i)], counts[static_cast<size_t>(j)], length,
                             factors.mean_count());
}

// A split edge's ghosts (held_edge.hpp) across the layer. An edge vertex j
// lies on the plane, its image is itself; its ghost at x_k + (s_j - s_k)
// has the image s_j + s_k - x_k. Each free vertex i near the plane joins the
// image of j's ghost with s_j of the pair's weight (the layer's bulk fiber
// to j's image is j itself, held), and each pair of ghosts joins one ghost
// to the other's image with s_i s_j of it: b = x_i + x_p - offset as the
// layer's own fibers.
void add_ghost_images(const Model& model, const MirrorLayer& layer, const HeldEdge& held_edge,
                      const PairFactors& factors, const Eigen::VectorXd& area0,
                      const std::vector<int>& near, std::vector<LayerFiber>* fibers) {
  const Eigen::MatrixXd& V = model.surface.V;
  const geom::FiberMask* mask = model.fibers.get();
  const std::vector<double> counts = factors.vertex_counts();
  const auto full_weight = [&](int i, int j, double length) {
    return layer_pair_weight(model, factors, counts, area0, i, j, length);
  };
  const std::vector<EdgeVertex> edge = held_edge_vertices(model, held_edge.held);
  for (const EdgeVertex& e : edge) {
    const int j = e.vertex, kj = e.neighbour;
    const Eigen::Vector3d sj = padded_row(V, j), skj = padded_row(V, kj);
    for (int i : near) {
      if (mask != nullptr && !mask->kept(i, j)) continue;
      const double length = (padded_row(V, i) - sj).norm();
      if (length >= layer.depth) continue;
      fibers->push_back({i, kj, sj + skj, length, e.free_share * full_weight(i, j, length)});
    }
    for (const EdgeVertex& g : edge) {  // each pair of ghosts once
      const int i = g.vertex, ki = g.neighbour;
      if (i >= j || (mask != nullptr && !mask->kept(i, j))) continue;
      const Eigen::Vector3d si = padded_row(V, i), ski = padded_row(V, ki);
      const double length = (si - sj).norm();
      if (length >= layer.depth) continue;
      fibers->push_back({ki, kj, sj + skj - si + ski, length,
                         e.free_share * g.free_share * full_weight(i, j, length)});
    }
  }
}

}  // namespace

std::vector<LayerFiber> mirror_layer_fibers(const Model& model, const MirrorLayer& layer,
                                            const PairFactors& factors,
                                            const Eigen::VectorXd& area0) {
  const Eigen::MatrixXd& V = model.surface.V;
  const int n = model.num_vertices();
  const double size = geom::bounding_box_diagonal(V);
  // Vertices on the plane are their own images: their fibers are the bulk's.
  std::vector<int> near;
  std::vector<double> height(static_cast<size_t>(n), 0.0);
  for (int v = 0; v < n; ++v) {
    height[static_cast<size_t>(v)] = (padded_row(V, v) - layer.point).dot(layer.normal);
    if (height[static_cast<size_t>(v)] > 1e-6 * size &&
        height[static_cast<size_t>(v)] < layer.depth)
      near.push_back(v);
  }
  const std::vector<double> counts = factors.vertex_counts();
  const geom::FiberMask* mask = model.fibers.get();
  const ClampedRegion region(model, layer);
  std::vector<LayerFiber> fibers;
  for (int i : near)
    for (int j : near) {
      if (i != j && mask != nullptr && !mask->kept(i, j)) continue;  // pruned or beyond the horizon
      const double hi = height[static_cast<size_t>(i)], hj = height[static_cast<size_t>(j)];
      const Eigen::Vector3d foot = padded_row(V, j) - hj * layer.normal;
      // As the term computes the fiber (b = x_i + x_j - 2 q_j): no strain at the reference.
      const double length = (padded_row(V, i) + padded_row(V, j) - 2.0 * foot).norm();
      const Eigen::Vector3d image = 2.0 * foot - padded_row(V, j);
      if (length >= layer.depth) continue;
      // Where the fiber from s_i to the image crosses the plane.
      if (!region.holds(padded_row(V, i) + hi / (hi + hj) * (image - padded_row(V, i)))) continue;
      const double weight = 0.5 * layer_pair_weight(model, factors, counts, area0, i, j, length);
      fibers.push_back({i, j, 2.0 * foot, length, weight});
    }
  if (const HeldEdge* edge = held_edge_of(model, layer.group))
    add_ghost_images(model, layer, *edge, factors, area0, near, &fibers);
  return fibers;
}

std::unique_ptr<EquilibriumTerm> make_mirror_layer_term(const TermContext& context,
                                                        const MirrorLayer& layer) {
  std::vector<PointFiber> fibers;
  for (const LayerFiber& f :
       mirror_layer_fibers(context.model, layer, context.pair_factors, context.area0))
    fibers.push_back({f.i, f.j, /*mirrored=*/true, f.twice_foot, f.length, f.weight});
  return make_point_fiber_term(context, std::move(fibers), "mirror layer",
                               EquilibriumTerm::Role::Support, layer.group);
}

}  // namespace fiberfluid::model
