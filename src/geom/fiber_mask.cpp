// SPDX-License-Identifier: GPL-3.0-or-later
#include "fiberfluid/geom/fiber_mask.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

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

FiberMask FiberMask::from_neighbours(std::vector<std::vector<int>> neighbours) {
  const int n = static_cast<int>(neighbours.size());
  FiberMask mask(0);
  mask.n_ = n;
  mask.sparse_ = true;
  std::vector<std::vector<int>> both(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
    for (int j : neighbours[static_cast<size_t>(i)]) {
      if (j < 0 || j >= n)
        throw std::invalid_argument("fiber mask: vertex " + std::to_string(i) + " has a partner " +
                                    std::to_string(j) + " out of range");
      if (j == i) continue;
      both[static_cast<size_t>(i)].push_back(j);
      both[static_cast<size_t>(j)].push_back(i);
    }
  for (std::vector<int>& list : both) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    list.shrink_to_fit();
  }
  mask.neighbours_ = std::move(both);
  return mask;
}

FiberMask FiberMask::as_sparse() const {
  if (sparse_) return *this;
  std::vector<std::vector<int>> lists(static_cast<size_t>(n_));
  for (int i = 0; i < n_; ++i)
    for_each_kept(i, [&](int j) {
      if (j > i) lists[static_cast<size_t>(i)].push_back(j);
    });
  return from_neighbours(std::move(lists));
}

FiberMask FiberMask::as_dense() const {
  if (!sparse_) return *this;
  FiberMask mask = none(n_);
  for (int i = 0; i < n_; ++i) for_each_kept(i, [&](int j) { mask.keep(i, j); });
  return mask;
}

bool FiberMask::kept(int i, int j) const {
  if (!sparse_) return kept_[index(i, j)] != 0;
  const std::vector<int>& list = neighbours_[static_cast<size_t>(i)];
  return std::binary_search(list.begin(), list.end(), j);
}

void FiberMask::keep(int i, int j) {
  if (i == j) return;
  if (!sparse_) {
    kept_[index(i, j)] = 1;
    kept_[index(j, i)] = 1;
    return;
  }
  for (const auto& [a, b] : {std::pair{i, j}, std::pair{j, i}}) {
    std::vector<int>& list = neighbours_[static_cast<size_t>(a)];
    const auto at = std::lower_bound(list.begin(), list.end(), b);
    if (at == list.end() || *at != b) list.insert(at, b);
  }
}

void FiberMask::prune(int i, int j) {
  if (!sparse_) {
    kept_[index(i, j)] = 0;
    kept_[index(j, i)] = 0;
    return;
  }
  for (const auto& [a, b] : {std::pair{i, j}, std::pair{j, i}}) {
    std::vector<int>& list = neighbours_[static_cast<size_t>(a)];
    const auto at = std::lower_bound(list.begin(), list.end(), b);
    if (at != list.end() && *at == b) list.erase(at);
  }
}

void FiberMask::keep_only_where(const FiberMask& other) {
  if (other.n_ != n_) throw std::invalid_argument("fiber masks of different sizes");
  if (!sparse_ && !other.sparse_) {
    for (size_t k = 0; k < kept_.size(); ++k) kept_[k] = kept_[k] & other.kept_[k];
  } else if (sparse_) {
    for (int i = 0; i < n_; ++i) {
      std::vector<int>& list = neighbours_[static_cast<size_t>(i)];
      list.erase(std::remove_if(list.begin(), list.end(), [&](int j) { return !other.kept(i, j); }),
                 list.end());
    }
  } else {
    for (int i = 0; i < n_; ++i)
      for (int j = 0; j < n_; ++j)
        if (kept_[index(i, j)] != 0 && !other.kept(i, j)) kept_[index(i, j)] = 0;
  }
}

const uint8_t* FiberMask::row(int i) const {
  if (sparse_) throw std::logic_error("FiberMask::row: the mask is stored as neighbour lists");
  return kept_.data() + index(i, 0);
}

const std::vector<int>& FiberMask::neighbours(int i) const {
  if (!sparse_) throw std::logic_error("FiberMask::neighbours: the mask is stored as a table");
  return neighbours_[static_cast<size_t>(i)];
}

long long FiberMask::num_kept() const {
  if (!sparse_) return std::accumulate(kept_.begin(), kept_.end(), 0LL) / 2;
  long long sum = 0;
  for (const std::vector<int>& list : neighbours_) sum += static_cast<long long>(list.size());
  return sum / 2;
}

std::vector<int> FiberMask::kept_per_vertex() const {
  std::vector<int> counts(static_cast<size_t>(n_));
  for (int i = 0; i < n_; ++i)
    counts[static_cast<size_t>(i)] =
        sparse_ ? static_cast<int>(neighbours_[static_cast<size_t>(i)].size())
                : std::accumulate(row(i), row(i) + n_, 0);
  return counts;
}

double FiberMask::bytes() const {
  if (!sparse_) return static_cast<double>(kept_.size());
  double sum = static_cast<double>(neighbours_.size() * sizeof(std::vector<int>));
  for (const std::vector<int>& list : neighbours_) sum += 4.0 * static_cast<double>(list.size());
  return sum;
}

}  // namespace fiberfluid::geom
