// SPDX-License-Identifier: GPL-3.0-or-later
// Sums of charges over inverse distances, phi_c(x_i) = sum_{j != i} q_jc / |x_i - x_j|,
// for every vertex i of a point set and several charge columns c at once, in
// less than O(N^2): a barycentric Lagrange treecode (L. Wang, R. Krasny,
// S. Tlupova, "A kernel-independent treecode based on barycentric Lagrange
// interpolation", Commun. Comput. Phys. 28 (2020) 1415-1436).
//
// The points are split into a binary tree of boxes. A box far enough from a
// target (its radius below theta times the distance to its centre) acts
// through (degree + 1)^3 Chebyshev proxy points carrying the charges
// interpolated onto them; a near box is summed directly. The error falls
// like theta^degree; each target is independent, so the result has the same
// bits for any thread count.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fiberfluid::model {

struct TreecodeOptions {
  int degree = 4;      // interpolation degree per axis
  double theta = 0.5;  // the far-field criterion: radius < theta * distance
  int leaf_size = 64;  // boxes of at most this many points are not split

  // The degree and theta measured to keep the relative error of the bulk
  // product below `tolerance` (1e-2 to 1e-10) on surface meshes
  // (experiments/scaling/treecode_benchmark.cpp).
  static TreecodeOptions for_tolerance(double tolerance);
};

class Treecode {
 public:
  // X: N x 3 point positions (coincident points are not allowed).
  Treecode(const Eigen::MatrixXd& X, TreecodeOptions options);

  // Q: N x k charges (k <= 8), rows by point. Returns the N x k potentials.
  Eigen::MatrixXd potentials(const Eigen::MatrixXd& Q) const;

  int size() const { return n_; }
  // Work of the last potentials() call: point-point and point-proxy terms.
  long long direct_terms() const { return direct_terms_; }
  long long proxy_terms() const { return proxy_terms_; }

 private:
  struct Node {
    double lo[3], hi[3], centre[3];
    double radius;   // half the box diagonal
    int begin, end;  // points [begin, end) in tree order
    int left = -1, right = -1;
    int proxy = -1;  // index among the nodes with proxies, or -1 (summed directly)
  };

  int build(int begin, int end);
  void interpolate_charges(const std::vector<double>& charges, int k,
                           std::vector<double>& proxy_charges) const;
  void evaluate_leaf(const Node& leaf, const std::vector<double>& charges,
                     const std::vector<double>& proxy_charges, int k, double* out,
                     std::vector<double>& scratch, std::vector<int>& stack, long long& direct,
                     long long& proxy) const;

  TreecodeOptions options_;
  int n_ = 0, proxies_per_node_ = 0;
  std::vector<double> chebyshev_;  // cos(m pi / degree), m = 0..degree
  std::vector<int> order_;         // tree position -> input row
  std::vector<double> x_[3];       // positions in tree order
  std::vector<Node> nodes_;
  std::vector<int> leaves_;         // the target batches
  std::vector<int> proxy_nodes_;    // the nodes with proxies
  std::vector<double> proxy_x_[3];  // their proxy points, proxies_per_node_ each
  mutable long long direct_terms_ = 0, proxy_terms_ = 0;
};

}  // namespace fiberfluid::model
