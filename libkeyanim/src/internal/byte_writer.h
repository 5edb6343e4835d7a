// Little-endian appending to a byte vector: the writer's side of byte_reader.h.
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "internal/byte_reader.h"

namespace keyanim::internal {

template <typename T>
inline void put_le(std::vector<uint8_t>& out, T v) {
  uint8_t b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  const T le = load_le<T>(b);  // a byte swap on big-endian hosts, else the identity
  std::memcpy(b, &le, sizeof(T));
  out.insert(out.end(), b, b + sizeof(T));
}

inline void put_bytes(std::vector<uint8_t>& out, const void* p, size_t n) {
  const auto* b = static_cast<const uint8_t*>(p);
  out.insert(out.end(), b, b + n);
}

}  // namespace keyanim::internal
