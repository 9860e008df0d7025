// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once

// A byte archive for results that travel between processes of one build (the
// ranks of an MPI run): numbers as their bytes, so a double arrives with the
// bits it left with. A type says its fields once, in a function
//   template <class Archive> void fields(Archive& a, T& t) { a(t.x, t.y); }
// that serves both directions: ByteWriter reads the fields, ByteReader sets
// them. Not a file format: no versions, no byte order (every rank runs the
// same program on the same kind of machine).

#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace fiberfluid {

class ByteWriter {
 public:
  template <class... T>
  void operator()(const T&... values) {
    (put(values), ...);
  }
  const std::string& bytes() const { return bytes_; }
  std::string take() { return std::move(bytes_); }

 private:
  template <class T>
  void put(const T& value) {
    if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
      bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
    } else if constexpr (std::is_same_v<T, std::string>) {
      put(static_cast<std::uint64_t>(value.size()));
      bytes_.append(value);
    } else if constexpr (std::is_base_of_v<Eigen::PlainObjectBase<T>, T>) {
      put(static_cast<std::int64_t>(value.rows()));
      put(static_cast<std::int64_t>(value.cols()));
      if (value.size() > 0)  // an empty matrix's data() may be null
        bytes_.append(reinterpret_cast<const char*>(value.data()),
                      sizeof(typename T::Scalar) * static_cast<size_t>(value.size()));
    } else {
      fields(*this, const_cast<T&>(value));  // a struct: its own field list
    }
  }
  template <class T>
  void put(const std::vector<T>& values) {
    put(static_cast<std::uint64_t>(values.size()));
    for (const T& v : values) put(v);
  }
  template <class K, class V>
  void put(const std::map<K, V>& values) {
    put(static_cast<std::uint64_t>(values.size()));
    for (const auto& [key, value] : values) put(key), put(value);
  }

  std::string bytes_;
};

class ByteReader {
 public:
  explicit ByteReader(const std::string& bytes) : bytes_(bytes) {}
  template <class... T>
  void operator()(T&... values) {
    (get(values), ...);
  }
  // True when every byte was read (a reader that stopped short read a
  // different layout than was written).
  bool finished() const { return at_ == bytes_.size(); }

 private:
  void take(void* to, size_t size) {
    if (size == 0) return;  // `to` may be null (an empty matrix, an empty string)
    if (size > bytes_.size() - at_)
      throw std::runtime_error("byte archive: the message ends early (" +
                               std::to_string(bytes_.size()) + " bytes)");
    std::memcpy(to, bytes_.data() + at_, size);
    at_ += size;
  }
  template <class T>
  void get(T& value) {
    if constexpr (std::is_arithmetic_v<T> || std::is_enum_v<T>) {
      take(&value, sizeof(T));
    } else if constexpr (std::is_same_v<T, std::string>) {
      value.resize(count());
      take(value.data(), value.size());
    } else if constexpr (std::is_base_of_v<Eigen::PlainObjectBase<T>, T>) {
      std::int64_t rows = 0, cols = 0;
      take(&rows, sizeof rows);
      take(&cols, sizeof cols);
      if (rows < 0 || cols < 0 ||
          static_cast<double>(rows) * static_cast<double>(cols) * sizeof(typename T::Scalar) >
              static_cast<double>(bytes_.size() - at_))
        throw std::runtime_error("byte archive: a matrix larger than the message");
      value.resize(rows, cols);
      take(value.data(), sizeof(typename T::Scalar) * static_cast<size_t>(value.size()));
    } else {
      fields(*this, value);
    }
  }
  template <class T>
  void get(std::vector<T>& values) {
    values.resize(count());
    for (T& v : values) get(v);
  }
  template <class K, class V>
  void get(std::map<K, V>& values) {
    values.clear();
    for (size_t n = count(); n > 0; --n) {
      K key;
      V value;
      get(key), get(value);
      values.emplace(std::move(key), std::move(value));
    }
  }
  // A container's length, never more than the bytes left could hold.
  size_t count() {
    std::uint64_t n = 0;
    take(&n, sizeof n);
    if (n > bytes_.size() - at_)
      throw std::runtime_error("byte archive: a length larger than the message");
    return static_cast<size_t>(n);
  }

  const std::string& bytes_;
  size_t at_ = 0;
};

}  // namespace fiberfluid
