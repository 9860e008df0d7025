// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fiberfluid::geom {

// Which pairs of vertices are joined by a bulk fiber: a symmetric N x N
// table of bytes (row-major, so a vertex's fibers are contiguous for the
// solvers' pair loops).
class FiberMask {
 public:
  explicit FiberMask(int num_vertices);     // every pair kept
  static FiberMask none(int num_vertices);  // no pair kept
  bool kept(int i, int j) const { return kept_[index(i, j)] != 0; }
  void prune(int i, int j);
  void keep(int i, int j);
  // Keeps a pair only where `other` keeps it too (a horizon and a pruning).
  void keep_only_where(const FiberMask& other);
  const uint8_t* row(int i) const { return kept_.data() + index(i, 0); }
  int num_vertices() const { return n_; }
  long long num_pairs() const { return static_cast<long long>(n_) * (n_ - 1) / 2; }
  long long num_kept() const;
  std::vector<int> kept_per_vertex() const;  // n_i

 private:
  std::size_t index(int i, int j) const { return static_cast<std::size_t>(i) * n_ + j; }
  int n_;
  std::vector<uint8_t> kept_;  // diagonal 0
};

}  // namespace fiberfluid::geom
