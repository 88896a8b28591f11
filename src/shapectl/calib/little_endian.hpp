#pragma once
// Numbers stored little-endian in a byte buffer (binary PLY, NumPy '<f8').
#include <algorithm>
#include <bit>
#include <cstring>

namespace shapectl {

// The T at `bytes` (sizeof(T) bytes, little-endian, any alignment).
template <class T>
T read_little_endian(const char* bytes) {
  char ordered[sizeof(T)];
  if constexpr (std::endian::native == std::endian::little)
    std::copy(bytes, bytes + sizeof(T), ordered);
  else std::reverse_copy(bytes, bytes + sizeof(T), ordered);
  T value;
  std::memcpy(&value, ordered, sizeof(T));
  return value;
}

}  // namespace shapectl
