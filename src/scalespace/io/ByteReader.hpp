#pragma once
// Bounds-checked reading of binary data held in memory, and scalar encoding for the binary
// writers (internal to the io layer). Every read
// checks the remaining size first and throws FileError(file, "byte N", ...) instead of reading
// past the end: a truncated or lying file can never cause an out-of-bounds access.
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/PointCloud.hpp"

namespace scalespace::io_detail {

inline std::string byteWhere(std::size_t offset) { return "byte " + std::to_string(offset); }

template <class T>
T byteSwapped(T value) {
  static_assert(std::is_trivially_copyable_v<T>);
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

/// Decodes a value of `type` stored at `bytes` (which must hold scalarTypeSize(type) bytes).
inline double decodeScalar(const char* bytes, ScalarType type, bool bigEndian) {
  auto get = [&](auto zero) {
    using T = decltype(zero);
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    if (bigEndian && sizeof(T) > 1) value = byteSwapped(value);
    return static_cast<double>(value);
  };
  switch (type) {
    case ScalarType::Int8:
      return get(std::int8_t{});
    case ScalarType::UInt8:
      return get(std::uint8_t{});
    case ScalarType::Int16:
      return get(std::int16_t{});
    case ScalarType::UInt16:
      return get(std::uint16_t{});
    case ScalarType::Int32:
      return get(std::int32_t{});
    case ScalarType::UInt32:
      return get(std::uint32_t{});
    case ScalarType::Float32:
      return get(float{});
    case ScalarType::Float64:
      return get(double{});
  }
  return 0.0;
}

/// Stores `value` (already converted with toStoredValue) as `type` at `out`.
inline void encodeScalar(double value, ScalarType type, bool bigEndian, char* out) {
  auto put = [&](auto typed) {
    if (bigEndian && sizeof(typed) > 1) typed = byteSwapped(typed);
    std::memcpy(out, &typed, sizeof(typed));
  };
  switch (type) {
    case ScalarType::Int8:
      return put(static_cast<std::int8_t>(value));
    case ScalarType::UInt8:
      return put(static_cast<std::uint8_t>(value));
    case ScalarType::Int16:
      return put(static_cast<std::int16_t>(value));
    case ScalarType::UInt16:
      return put(static_cast<std::uint16_t>(value));
    case ScalarType::Int32:
      return put(static_cast<std::int32_t>(value));
    case ScalarType::UInt32:
      return put(static_cast<std::uint32_t>(value));
    case ScalarType::Float32:
      return put(static_cast<float>(value));
    case ScalarType::Float64:
      return put(value);
  }
}

class ByteReader {
 public:
  ByteReader(std::string_view data, const std::string& file) : data_(data), file_(file) {}

  std::size_t offset() const { return offset_; }
  std::size_t size() const { return data_.size(); }
  std::size_t remaining() const { return data_.size() - offset_; }
  const std::string& file() const { return file_; }

  /// Throws unless `n` more bytes are available; `what` says what was being read.
  void require(std::size_t n, const char* what) const {
    if (n > remaining())
      throw FileError(file_, byteWhere(offset_),
                      std::string("unexpected end of file while reading ") + what + " (" +
                          std::to_string(n) + " bytes needed, " + std::to_string(remaining()) +
                          " left)",
                      "the file is truncated or its header declares more data than it holds");
  }
  void seek(std::size_t position, const char* what) {
    if (position > data_.size())
      throw FileError(file_, byteWhere(offset_),
                      std::string(what) + " points to byte " + std::to_string(position) +
                          " beyond the end of the file (" + std::to_string(data_.size()) +
                          " bytes)",
                      "the file is truncated or its header is corrupt");
    offset_ = position;
  }
  void skip(std::size_t n, const char* what) {
    require(n, what);
    offset_ += n;
  }
  /// Pointer to the next `n` bytes, then advances.
  const char* take(std::size_t n, const char* what) {
    require(n, what);
    const char* p = data_.data() + offset_;
    offset_ += n;
    return p;
  }
  template <class T>
  T read(const char* what, bool bigEndian = false) {
    const char* p = take(sizeof(T), what);
    T value;
    std::memcpy(&value, p, sizeof(T));
    if (bigEndian && sizeof(T) > 1) value = byteSwapped(value);
    return value;
  }
  double readScalar(ScalarType type, bool bigEndian, const char* what) {
    return decodeScalar(take(scalarTypeSize(type), what), type, bigEndian);
  }

 private:
  std::string_view data_;
  const std::string& file_;
  std::size_t offset_ = 0;
};

/// a * b, or false when it overflows size_t (lying headers declare absurd counts).
inline bool multiplyChecked(std::size_t a, std::size_t b, std::size_t& result) {
  return !__builtin_mul_overflow(a, b, &result);
}

}  // namespace scalespace::io_detail
