// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fiberfluid::geom {

// Which pairs of vertices are joined by a bulk fiber, stored one of two ways:
//   dense:  a symmetric N x N table of bytes (row-major, so a vertex's fibers
//           are contiguous for the tiled pair loops); N^2 bytes;
//   sparse: each vertex's kept partners, sorted (neighbour lists); memory N
//           times the neighbours. A horizon that keeps few pairs is stored so
//           (horizon_fibers), and the pair loops then visit only its pairs.
// Both answer the same questions; row() is the dense table's alone.
class FiberMask {
 public:
  explicit FiberMask(int num_vertices);     // every pair kept (dense)
  static FiberMask none(int num_vertices);  // no pair kept (dense)
  // Sparse, from each vertex's partners (made symmetric, sorted, without
  // repeats or i itself). Throws std::invalid_argument for a partner out of range.
  static FiberMask from_neighbours(std::vector<std::vector<int>> neighbours);

  bool sparse() const { return sparse_; }
  FiberMask as_sparse() const;
  FiberMask as_dense() const;

  bool kept(int i, int j) const;
  void prune(int i, int j);
  void keep(int i, int j);
  // Keeps a pair only where `other` keeps it too (a horizon and a pruning).
  void keep_only_where(const FiberMask& other);
  // Dense only: vertex i's row of the table (std::logic_error when sparse).
  const uint8_t* row(int i) const;
  // Sparse only: vertex i's kept partners, ascending (std::logic_error when dense).
  const std::vector<int>& neighbours(int i) const;
  // body(j) for each partner j of i kept, ascending, in either storage.
  template <class Body>
  void for_each_kept(int i, Body&& body) const {
    if (sparse_) {
      for (int j : neighbours_[static_cast<size_t>(i)]) body(j);
    } else {
      const uint8_t* r = row(i);
      for (int j = 0; j < n_; ++j)
        if (r[j] != 0) body(j);
    }
  }
  int num_vertices() const { return n_; }
  long long num_pairs() const { return static_cast<long long>(n_) * (n_ - 1) / 2; }
  long long num_kept() const;
  std::vector<int> kept_per_vertex() const;  // n_i
  // The bytes the storage takes (for the resource reports).
  double bytes() const;

 private:
  std::size_t index(int i, int j) const { return static_cast<std::size_t>(i) * n_ + j; }
  int n_;
  bool sparse_ = false;
  std::vector<uint8_t> kept_;                 // dense: diagonal 0
  std::vector<std::vector<int>> neighbours_;  // sparse
};

}  // namespace fiberfluid::geom
