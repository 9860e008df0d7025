// SPDX-License-Identifier: GPL-3.0-or-later
#include "geom/fiber_mask.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace fiberfluid::geom {

FiberMask::FiberMask(int num_vertices)
    : n_(num_vertices), kept_(static_cast<size_t>(num_vertices) * num_vertices, 1) {
  for (int i = 0; i < n_; ++i) kept_[index(i, i)] = 0;
}

FiberMask FiberMask::none(int num_vertices) {
  FiberMask mask(num_vertices);
  std::fill(mask.kept_.begin(), mask.kept_.end(), uint8_t{0});
  return mask;
}

void FiberMask::keep(int i, int j) {
  if (i == j) return;
  kept_[index(i, j)] = 1;
  kept_[index(j, i)] = 1;
}

void FiberMask::keep_only_where(const FiberMask& other) {
  if (other.n_ != n_) throw std::invalid_argument("fiber masks of different sizes");
  for (size_t k = 0; k < kept_.size(); ++k) kept_[k] = kept_[k] & other.kept_[k];
}

void FiberMask::prune(int i, int j) {
  kept_[index(i, j)] = 0;
  kept_[index(j, i)] = 0;
}

long long FiberMask::num_kept() const {
  return std::accumulate(kept_.begin(), kept_.end(), 0LL) / 2;
}

std::vector<int> FiberMask::kept_per_vertex() const {
  std::vector<int> counts(static_cast<size_t>(n_));
  for (int i = 0; i < n_; ++i)
    counts[static_cast<size_t>(i)] = std::accumulate(row(i), row(i) + n_, 0);
  return counts;
}

}  // namespace fiberfluid::geom
