// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/model/treecode.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "fiberfluid/model/vector_clones.hpp"

namespace fiberfluid::model {

namespace {

constexpr int kMaxColumns = 8;

// out[t * K + c] += sum_s q[c][s] / |x_t - y_s| for the targets t and sources
// s of one block; a source at a target's own position adds nothing (the sums
// leave the point itself out). K charge columns, q column c at q + c * stride;
// r: room for `sources` inverse distances.
template <int K>
FIBERFLUID_VECTOR_CLONES void block_sum(const double* tx, const double* ty, const double* tz,
                                        int targets, const double* sx, const double* sy,
                                        const double* sz, int sources, const double* q,
                                        size_t stride, double* r, double* out) {
  for (int t = 0; t < targets; ++t) {
    const double px = tx[t], py = ty[t], pz = tz[t];
#pragma omp simd
    for (int s = 0; s < sources; ++s) {
      const double dx = sx[s] - px, dy = sy[s] - py, dz = sz[s] - pz;
      const double d2 = dx * dx + dy * dy + dz * dz;
      // Branch-free, so that the loop vectorises: 0 at the target itself.
      const bool apart = d2 > 0.0;
      r[s] = (apart ? 1.0 : 0.0) / std::sqrt(apart ? d2 : 1.0);
    }
    for (int c = 0; c < K; ++c) {
      const double* column = q + static_cast<size_t>(c) * stride;
      double sum = 0.0;
#pragma omp simd reduction(+ : sum)
      for (int s = 0; s < sources; ++s) sum += column[s] * r[s];
      out[t * K + c] += sum;
    }
  }
}

using BlockSum = void (*)(const double*, const double*, const double*, int, const double*,
                          const double*, const double*, int, const double*, size_t, double*,
                          double*);

BlockSum block_sum_for(int k) {
  switch (k) {
    case 1:
      return block_sum<1>;
    case 2:
      return block_sum<2>;
    case 3:
      return block_sum<3>;
    case 4:
      return block_sum<4>;
    case 5:
      return block_sum<5>;
    case 6:
      return block_sum<6>;
    case 7:
      return block_sum<7>;
    default:
      return block_sum<8>;
  }
}

// The barycentric Lagrange basis at y of the Chebyshev points of the second
// kind t_m = centre + half * chebyshev[m], chebyshev[m] = cos(m pi / degree):
// L_m(y), m = 0..degree.
void lagrange_basis(double y, double centre, double half, const std::vector<double>& chebyshev,
                    double* basis) {
  const int degree = static_cast<int>(chebyshev.size()) - 1;
  double total = 0.0;
  for (int m = 0; m <= degree; ++m) {
    const double t = centre + half * chebyshev[static_cast<size_t>(m)];
    if (y == t) {  // on a node: the basis is that node's indicator
      std::fill(basis, basis + degree + 1, 0.0);
      basis[m] = 1.0;
      return;
    }
    const double weight = (m % 2 == 0 ? 1.0 : -1.0) * (m == 0 || m == degree ? 0.5 : 1.0);
    basis[m] = weight / (y - t);
    total += basis[m];
  }
  for (int m = 0; m <= degree; ++m) basis[m] /= total;
}

// Half-widths of the interpolation box: a flat box (a planar cluster) is
// given some thickness so that its Chebyshev points stay distinct.
void interpolation_box(const double* lo, const double* hi, double* centre, double* half) {
  double widest = 0.0;
  for (int a = 0; a < 3; ++a) widest = std::max(widest, 0.5 * (hi[a] - lo[a]));
  for (int a = 0; a < 3; ++a) {
    centre[a] = 0.5 * (lo[a] + hi[a]);
    half[a] = std::max(0.5 * (hi[a] - lo[a]), 1e-3 * widest);
  }
}

}  // namespace

TreecodeOptions TreecodeOptions::for_tolerance(double tolerance) {
  if (!(tolerance >= 1e-10 && tolerance <= 1e-2))
    throw std::invalid_argument("treecode tolerance must be between 1e-10 and 1e-2");
  TreecodeOptions o;
  // Measured on a 10,242-vertex icosphere (treecode_benchmark): the bulk
  // product's relative error (2-norm, and the largest row's) is 5 to 20 times
  // below the tolerance named; the table in README shows other sizes.
  o.theta = 0.7;
  if (tolerance >= 1e-3) {
    o.degree = 3;
  } else if (tolerance >= 1e-4) {
    o.degree = 4;
  } else if (tolerance >= 1e-5) {
    o.degree = 5;
  } else if (tolerance >= 1e-6) {
    o.degree = 6;
  } else if (tolerance >= 1e-8) {
    o.degree = 8, o.theta = 0.6;
  } else {
    o.degree = 9, o.theta = 0.6;
  }
  return o;
}

Treecode::Treecode(const Eigen::MatrixXd& X, TreecodeOptions options)
    : options_(options), n_(static_cast<int>(X.rows())) {
  if (X.cols() != 3) throw std::invalid_argument("the treecode sums over 3D points");
  if (options_.degree < 1 || !(options_.theta > 0.0 && options_.theta < 1.0) ||
      options_.leaf_size < 1)
    throw std::invalid_argument(
        "treecode options: expected degree >= 1, 0 < theta < 1, leaves >= 1");
  const int p = options_.degree + 1;
  proxies_per_node_ = p * p * p;
  for (int m = 0; m < p; ++m) chebyshev_.push_back(std::cos(M_PI * m / options_.degree));
  order_.resize(static_cast<size_t>(n_));
  std::iota(order_.begin(), order_.end(), 0);
  for (int a = 0; a < 3; ++a) {
    x_[a].resize(static_cast<size_t>(n_));
    for (int i = 0; i < n_; ++i) x_[a][static_cast<size_t>(i)] = X(i, a);
  }
  nodes_.reserve(static_cast<size_t>(4 * n_ / std::max(1, options_.leaf_size) + 4));
  if (n_ > 0) build(0, n_);
  // Positions in tree order, and the proxy points of the nodes that have them.
  for (int a = 0; a < 3; ++a) {
    std::vector<double> sorted(static_cast<size_t>(n_));
    for (int t = 0; t < n_; ++t)
      sorted[static_cast<size_t>(t)] = X(order_[static_cast<size_t>(t)], a);
    x_[a] = std::move(sorted);
  }
  for (Node& node : nodes_) {
    if (node.left < 0) leaves_.push_back(static_cast<int>(&node - nodes_.data()));
    if (node.end - node.begin <= proxies_per_node_) continue;  // direct is cheaper
    node.proxy = static_cast<int>(proxy_nodes_.size());
    proxy_nodes_.push_back(static_cast<int>(&node - nodes_.data()));
    double centre[3], half[3];
    interpolation_box(node.lo, node.hi, centre, half);
    for (int i = 0; i < p; ++i)
      for (int j = 0; j < p; ++j)
        for (int k = 0; k < p; ++k) {
          proxy_x_[0].push_back(centre[0] + half[0] * chebyshev_[static_cast<size_t>(i)]);
          proxy_x_[1].push_back(centre[1] + half[1] * chebyshev_[static_cast<size_t>(j)]);
          proxy_x_[2].push_back(centre[2] + half[2] * chebyshev_[static_cast<size_t>(k)]);
        }
  }
}

// Splits [begin, end) of order_ at the middle of its box's longest side.
int Treecode::build(int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node node;
  node.begin = begin;
  node.end = end;
  for (int a = 0; a < 3; ++a) {
    node.lo[a] = HUGE_VAL;
    node.hi[a] = -HUGE_VAL;
    for (int t = begin; t < end; ++t) {
      const double v = x_[a][static_cast<size_t>(order_[static_cast<size_t>(t)])];
      node.lo[a] = std::min(node.lo[a], v);
      node.hi[a] = std::max(node.hi[a], v);
    }
    node.centre[a] = 0.5 * (node.lo[a] + node.hi[a]);
  }
  node.radius =
      0.5 * std::sqrt(std::pow(node.hi[0] - node.lo[0], 2) + std::pow(node.hi[1] - node.lo[1], 2) +
                      std::pow(node.hi[2] - node.lo[2], 2));
  if (end - begin > options_.leaf_size) {
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (node.hi[a] - node.lo[a] > node.hi[axis] - node.lo[axis]) axis = a;
    const auto first = order_.begin() + begin, last = order_.begin() + end;
    auto middle = std::partition(
        first, last, [&](int i) { return x_[axis][static_cast<size_t>(i)] < node.centre[axis]; });
    if (middle == first || middle == last) {  // all on one side: split by count
      middle = first + (end - begin) / 2;
      std::nth_element(first, middle, last, [&](int i, int j) {
        return x_[axis][static_cast<size_t>(i)] < x_[axis][static_cast<size_t>(j)];
      });
    }
    const int split = static_cast<int>(middle - order_.begin());
    node.left = build(begin, split);
    node.right = build(split, end);
  }
  nodes_[static_cast<size_t>(index)] = node;
  return index;
}

// The charges each proxy node carries: sum over its points of the Lagrange
// basis at the point times the point's charge (the upward pass).
void Treecode::interpolate_charges(const std::vector<double>& charges, int k,
                                   std::vector<double>& proxy_charges) const {
  const int p = options_.degree + 1, P = proxies_per_node_;
  proxy_charges.assign(proxy_nodes_.size() * static_cast<size_t>(k * P), 0.0);
#pragma omp parallel
  {
    std::vector<double> bx(static_cast<size_t>(p)), by(static_cast<size_t>(p)),
        bz(static_cast<size_t>(p)), weight(static_cast<size_t>(P));
#pragma omp for schedule(dynamic, 1)
    for (size_t m = 0; m < proxy_nodes_.size(); ++m) {
      const Node& node = nodes_[static_cast<size_t>(proxy_nodes_[m])];
      double centre[3], half[3];
      interpolation_box(node.lo, node.hi, centre, half);
      double* out = proxy_charges.data() + m * static_cast<size_t>(k * P);
      for (int t = node.begin; t < node.end; ++t) {
        const size_t s = static_cast<size_t>(t);
        lagrange_basis(x_[0][s], centre[0], half[0], chebyshev_, bx.data());
        lagrange_basis(x_[1][s], centre[1], half[1], chebyshev_, by.data());
        lagrange_basis(x_[2][s], centre[2], half[2], chebyshev_, bz.data());
        for (int i = 0; i < p; ++i)
          for (int j = 0; j < p; ++j) {
            const double wij = bx[static_cast<size_t>(i)] * by[static_cast<size_t>(j)];
            for (int l = 0; l < p; ++l)
              weight[static_cast<size_t>((i * p + j) * p + l)] = wij * bz[static_cast<size_t>(l)];
          }
        for (int c = 0; c < k; ++c) {
          const double q = charges[static_cast<size_t>(c) * static_cast<size_t>(n_) + s];
          double* column = out + c * P;
          for (int r = 0; r < P; ++r) column[r] += weight[static_cast<size_t>(r)] * q;
        }
      }
    }
  }
}

// The sums at the points of one leaf: its interaction list from one
// traversal (a node is far for the whole leaf when the sum of the two radii
// is below theta times the distance of their centres), then one block sum
// per node in the list.
void Treecode::evaluate_leaf(const Node& leaf, const std::vector<double>& charges,
                             const std::vector<double>& proxy_charges, int k, double* out,
                             std::vector<double>& scratch, std::vector<int>& stack,
                             long long& direct, long long& proxy) const {
  const BlockSum sum = block_sum_for(k);
  const int P = proxies_per_node_, targets = leaf.end - leaf.begin;
  const size_t b = static_cast<size_t>(leaf.begin);
  const double* tx = x_[0].data() + b;
  const double* ty = x_[1].data() + b;
  const double* tz = x_[2].data() + b;
  std::fill(out, out + static_cast<size_t>(targets * k), 0.0);
  stack.assign(1, 0);
  while (!stack.empty()) {
    const Node& node = nodes_[static_cast<size_t>(stack.back())];
    stack.pop_back();
    const double dx = leaf.centre[0] - node.centre[0], dy = leaf.centre[1] - node.centre[1],
                 dz = leaf.centre[2] - node.centre[2];
    const double reach = node.radius + leaf.radius;
    if (node.proxy >= 0 &&
        reach * reach < options_.theta * options_.theta * (dx * dx + dy * dy + dz * dz)) {
      const size_t base = static_cast<size_t>(node.proxy) * static_cast<size_t>(P);
      sum(tx, ty, tz, targets, proxy_x_[0].data() + base, proxy_x_[1].data() + base,
          proxy_x_[2].data() + base, P,
          proxy_charges.data() + static_cast<size_t>(node.proxy) * static_cast<size_t>(k * P),
          static_cast<size_t>(P), scratch.data(), out);
      proxy += static_cast<long long>(targets) * P;
    } else if (node.proxy < 0 || node.left < 0) {
      const size_t s = static_cast<size_t>(node.begin);
      const int sources = node.end - node.begin;
      sum(tx, ty, tz, targets, x_[0].data() + s, x_[1].data() + s, x_[2].data() + s, sources,
          charges.data() + s, static_cast<size_t>(n_), scratch.data(), out);
      direct += static_cast<long long>(targets) * sources;
    } else {
      stack.push_back(node.right);
      stack.push_back(node.left);
    }
  }
}

Eigen::MatrixXd Treecode::potentials(const Eigen::MatrixXd& Q) const {
  const int k = static_cast<int>(Q.cols());
  if (Q.rows() != n_ || k < 1 || k > kMaxColumns)
    throw std::invalid_argument("treecode charges: expected N rows and 1 to 8 columns");
  // Charges column by column in tree order.
  std::vector<double> charges(static_cast<size_t>(k) * static_cast<size_t>(n_));
  for (int c = 0; c < k; ++c)
    for (int t = 0; t < n_; ++t)
      charges[static_cast<size_t>(c) * static_cast<size_t>(n_) + static_cast<size_t>(t)] =
          Q(order_[static_cast<size_t>(t)], c);
  std::vector<double> proxy_charges;
  interpolate_charges(charges, k, proxy_charges);

  Eigen::MatrixXd out(n_, k);
  long long direct = 0, proxy = 0;
#pragma omp parallel reduction(+ : direct, proxy)
  {
    std::vector<double> sums(static_cast<size_t>(options_.leaf_size * k));
    std::vector<double> scratch(
        static_cast<size_t>(std::max(proxies_per_node_, options_.leaf_size)));
    std::vector<int> stack;
#pragma omp for schedule(dynamic, 4)
    for (size_t l = 0; l < leaves_.size(); ++l) {
      const Node& leaf = nodes_[static_cast<size_t>(leaves_[l])];
      evaluate_leaf(leaf, charges, proxy_charges, k, sums.data(), scratch, stack, direct, proxy);
      for (int t = leaf.begin; t < leaf.end; ++t)
        for (int c = 0; c < k; ++c)
          out(order_[static_cast<size_t>(t)], c) =
              sums[static_cast<size_t>((t - leaf.begin) * k + c)];
    }
  }
  direct_terms_ = direct;
  proxy_terms_ = proxy;
  return out;
}

}  // namespace fiberfluid::model
