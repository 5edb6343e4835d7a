// Bounds-checked little-endian reading of untrusted bytes: every read says whether the bytes
// were there, so no caller can run past the end of a buffer.
#pragma once
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace keyanim::internal {

template <typename T>
inline T load_le(const uint8_t* p) noexcept {
  T v;
  std::memcpy(&v, p, sizeof(T));
  if constexpr (std::endian::native == std::endian::big && sizeof(T) > 1) {
    uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    for (size_t i = 0; i < sizeof(T) / 2; ++i) {
      const uint8_t t = b[i];
      b[i] = b[sizeof(T) - 1 - i];
      b[sizeof(T) - 1 - i] = t;
    }
    std::memcpy(&v, b, sizeof(T));
  }
  return v;
}

class ByteReader {
 public:
  ByteReader() = default;
  ByteReader(const uint8_t* data, size_t size) noexcept : data_(data), size_(size) {}

  size_t pos() const noexcept { return pos_; }
  size_t remaining() const noexcept { return size_ - pos_; }
  bool at_end() const noexcept { return pos_ == size_; }

  // Each returns false (and leaves the position unchanged) when fewer bytes remain.
  template <typename T>
  bool read(T& out) noexcept {
    if (remaining() < sizeof(T)) return false;
    out = load_le<T>(data_ + pos_);
    pos_ += sizeof(T);
    return true;
  }
  bool bytes(size_t n, const uint8_t*& out) noexcept {
    if (remaining() < n) return false;
    out = data_ + pos_;
    pos_ += n;
    return true;
  }
  bool skip(size_t n) noexcept {
    if (remaining() < n) return false;
    pos_ += n;
    return true;
  }

 private:
  const uint8_t* data_ = nullptr;
  size_t size_ = 0;
  size_t pos_ = 0;
};

}  // namespace keyanim::internal
