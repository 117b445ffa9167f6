// NumPy .npy arrays and .npz archives (zip files of .npy members), read and written.
//
// Supported: little-endian, C-order arrays of f4, f8, i1, i4, i8, u1, u4, u8, b1 (f2 as tensors only) and
// unicode strings (<U n), any rank including 0-d scalars; .npz members stored or deflated.
// Big-endian, Fortran-order, object and structured arrays are refused with a clear error.
// The .npy header is parsed by hand (format spec: numpy.lib.format): Debian ships no npy
// library, and the header is one short Python dict literal.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "core/util/error.h"

namespace bimart {

// One array. `dtype` is the numpy type code without byte order: "f4", "f8", "i1", "i4",
// "i8", "u1", "u4", "u8", "b1", or "U<n>" (n UCS-4 code points per element). `data` holds
// the elements in C order, little-endian; a 0-d scalar has an empty shape and one element.
struct NpyArray {
  std::string dtype;
  std::vector<int64_t> shape;
  std::vector<uint8_t> data;

  int64_t num_elements() const;  // product of shape (1 for a scalar)
  int item_size() const;         // bytes per element; throws for an unknown dtype
  bool is_numeric() const;       // a number or bool dtype (not a string)
  std::string shape_str() const;  // "(2, 3)", "()" as numpy prints it
  // Throws bimart::Error unless dtype is known and data has exactly the right size.
  void check(const std::string& what) const;
};

// The dtype code of a C++ element type.
template <class T>
std::string npy_dtype() {
  if constexpr (std::is_same_v<T, double>) return "f8";
  else if constexpr (std::is_same_v<T, float>) return "f4";
  else if constexpr (std::is_same_v<T, bool>) return "b1";
  else if constexpr (std::is_same_v<T, int8_t>) return "i1";
  else if constexpr (std::is_same_v<T, uint8_t>) return "u1";
  else if constexpr (std::is_same_v<T, int32_t>) return "i4";
  else if constexpr (std::is_same_v<T, uint32_t>) return "u4";
  else if constexpr (std::is_same_v<T, int64_t>) return "i8";
  else if constexpr (std::is_same_v<T, uint64_t>) return "u8";
  else static_assert(sizeof(T) == 0, "no npy dtype for this type");
}

// Builds an array of `shape` from `values` given in C order; the count must match.
template <class T>
NpyArray make_npy(const T* values, std::vector<int64_t> shape) {
  NpyArray a{npy_dtype<T>(), std::move(shape), {}};
  for (int64_t d : a.shape)
    if (d < 0) throw Error("make_npy: negative extent in shape " + a.shape_str());
  a.data.resize(static_cast<size_t>(a.num_elements()) * sizeof(T));
  if (!a.data.empty()) std::memcpy(a.data.data(), values, a.data.size());
  return a;
}
template <class T, class = std::enable_if_t<!std::is_same_v<T, bool>>>
NpyArray make_npy(const std::vector<T>& values, std::vector<int64_t> shape) {
  const NpyArray empty{npy_dtype<T>(), shape, {}};
  int64_t n = 1;
  for (int64_t d : shape) n *= d;
  if (n < 0 || static_cast<size_t>(n) != values.size())
    throw Error("make_npy: " + std::to_string(values.size()) + " values do not fill shape " +
                empty.shape_str());
  return make_npy(values.data(), std::move(shape));
}
// 1-D array of the vector's length.
template <class T, class = std::enable_if_t<!std::is_same_v<T, bool>>>
NpyArray make_npy(const std::vector<T>& values) {
  return make_npy(values.data(), {static_cast<int64_t>(values.size())});
}
// 0-d scalar.
template <class T>
NpyArray make_npy_scalar(T value) {
  return make_npy(&value, {});
}
// A matrix, read row by row, as a 2-D array [rows, cols], or with `shape` given (same count).
template <class Derived>
NpyArray make_npy(const Eigen::DenseBase<Derived>& m, std::vector<int64_t> shape = {}) {
  using T = typename Derived::Scalar;
  Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rm = m;
  if (shape.empty()) shape = {static_cast<int64_t>(rm.rows()), static_cast<int64_t>(rm.cols())};
  return make_npy(std::vector<T>(rm.data(), rm.data() + rm.size()), std::move(shape));
}
// Unicode strings (UTF-8 in, "U<n>" with n = the longest string's code points).
NpyArray make_npy_strings(const std::vector<std::string>& values, std::vector<int64_t> shape);

namespace detail {
[[noreturn]] void throw_conversion(const std::string& what, const std::string& dtype,
                                   double value, const char* target);
[[noreturn]] void throw_not_numeric(const std::string& what, const std::string& dtype);

template <class T, class S>
T convert_element(S s, const std::string& what, const std::string& dtype) {
  if constexpr (std::is_floating_point_v<T>) {
    return static_cast<T>(s);
  } else if constexpr (std::is_floating_point_v<S>) {
    // Float to integer: only whole numbers in range.
    if (!std::isfinite(s) || s != std::trunc(s) ||
        static_cast<long double>(s) < static_cast<long double>(std::numeric_limits<T>::min()) ||
        static_cast<long double>(s) > static_cast<long double>(std::numeric_limits<T>::max()))
      throw_conversion(what, dtype, static_cast<double>(s), "a whole number in range");
    return static_cast<T>(s);
  } else {
    // Integer to integer: range-checked.
    if constexpr (std::is_signed_v<S>) {
      if (s < 0 && !std::is_signed_v<T>) throw_conversion(what, dtype, double(s), "unsigned");
      if (s < 0 && static_cast<int64_t>(s) < static_cast<int64_t>(std::numeric_limits<T>::min()))
        throw_conversion(what, dtype, double(s), "in range");
    }
    if (s > 0 && static_cast<uint64_t>(s) > static_cast<uint64_t>(std::numeric_limits<T>::max()))
      throw_conversion(what, dtype, double(s), "in range");
    return static_cast<T>(s);
  }
}

template <class T, class S>
void convert_all(const NpyArray& a, std::vector<T>& out, const std::string& what) {
  const size_t n = out.size();
  for (size_t i = 0; i < n; ++i) {
    S s;
    std::memcpy(&s, a.data.data() + i * sizeof(S), sizeof(S));
    out[i] = convert_element<T>(s, what, a.dtype);
  }
}
}  // namespace detail

// All elements in C order, converted to T (a floating or integer type). Integers and bools
// convert to floats freely; to an integer T only whole numbers in T's range convert, else a
// bimart::Error naming `what`.
template <class T>
std::vector<T> as_vector(const NpyArray& a, const std::string& what = "array") {
  a.check(what);
  std::vector<T> out(static_cast<size_t>(a.num_elements()));
  const std::string& d = a.dtype;
  if (d == "f8") detail::convert_all<T, double>(a, out, what);
  else if (d == "f4") detail::convert_all<T, float>(a, out, what);
  else if (d == "i8") detail::convert_all<T, int64_t>(a, out, what);
  else if (d == "i4") detail::convert_all<T, int32_t>(a, out, what);
  else if (d == "i1") detail::convert_all<T, int8_t>(a, out, what);
  else if (d == "u8") detail::convert_all<T, uint64_t>(a, out, what);
  else if (d == "u4") detail::convert_all<T, uint32_t>(a, out, what);
  else if (d == "u1" || d == "b1") detail::convert_all<T, uint8_t>(a, out, what);
  else detail::throw_not_numeric(what, d);
  return out;
}

// A numeric array of rank <= 2 as a double matrix: 0-d -> 1x1, [n] -> n x 1, [r, c] -> r x c.
Eigen::MatrixXd to_eigen(const NpyArray& a, const std::string& what = "array");
// Any numeric array with rows * cols elements, reshaped in C order (row r = elements
// r*cols .. r*cols+cols-1), e.g. [V, 3, 10] -> 3V x 10.
Eigen::MatrixXd to_eigen(const NpyArray& a, Eigen::Index rows, Eigen::Index cols,
                         const std::string& what = "array");
// The strings of a "U<n>" array in C order, as UTF-8, trailing NULs removed.
std::vector<std::string> as_strings(const NpyArray& a, const std::string& what = "array");

// The bytes of a .npy file (format version 1.0, header padded to 64 bytes as numpy does).
std::vector<uint8_t> serialize_npy(const NpyArray& a);
// Parses the bytes of a .npy file; errors name `what` (a file, or file and key).
NpyArray parse_npy(const uint8_t* bytes, size_t size, const std::string& what);
NpyArray read_npy(const std::string& path);
void write_npy(const std::string& path, const NpyArray& a);  // atomic

enum class NpzCompression { Deflate, Store };

// A .npz archive: arrays by key (the member name without ".npy"). Errors name the file
// and, where it applies, the key.
class NpzFile {
 public:
  NpzFile() = default;

  // Reads every .npy member (stored or deflated); other members are ignored.
  static NpzFile read(const std::string& path);
  // Atomic: the archive is built in memory and renamed into place.
  void write(const std::string& path, NpzCompression compression = NpzCompression::Deflate) const;

  bool contains(const std::string& key) const { return arrays_.count(key) != 0; }
  // Throws bimart::Error naming the file, the key and the keys present.
  const NpyArray& get(const std::string& key) const;
  // As get(), and checks the shape; -1 in `shape` matches any extent.
  const NpyArray& get(const std::string& key, const std::vector<int64_t>& shape) const;
  void set(const std::string& key, NpyArray array);
  std::vector<std::string> keys() const;  // sorted
  size_t size() const { return arrays_.size(); }

  // Typed access with messages naming the file and key.
  template <class T>
  std::vector<T> vector(const std::string& key) const { return as_vector<T>(get(key), where(key)); }
  Eigen::MatrixXd matrix(const std::string& key) const { return to_eigen(get(key), where(key)); }

  // The file read from ("" for one built in memory).
  const std::string& path() const { return path_; }
  // "<file>: array '<key>'", for messages.
  std::string where(const std::string& key) const;

 private:
  std::string path_;
  std::map<std::string, NpyArray> arrays_;
};

}  // namespace bimart
