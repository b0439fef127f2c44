// Reading a libFuzzer input as a stream of values, for the targets of fuzz/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace maf_fuzz {

/// Reads a T from the input at @p p (@p n bytes left), advancing both; the bytes past the end read as zero.
template <class T>
T take(const std::uint8_t*& p, std::size_t& n)
{
  T v{};
  const std::size_t k = n < sizeof(T) ? n : sizeof(T);
  std::memcpy(&v, p, k);
  p += k;
  n -= k;
  return v;
}

}  // namespace maf_fuzz
