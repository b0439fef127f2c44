/**
 * @file aligned_vector.hpp
 * @brief std::vector with cache-line (64-byte) aligned storage, for the grids' SIMD loops.
 */
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace map_aided_fusion {
namespace core {

/// Minimal allocator returning storage aligned to @p Alignment bytes.
template <typename T, std::size_t Alignment = 64>
struct AlignedAllocator
{
  using value_type = T;
  template <typename U>
  struct rebind
  {
    using other = AlignedAllocator<U, Alignment>;
  };
  AlignedAllocator() noexcept = default;
  template <typename U>
  AlignedAllocator(const AlignedAllocator<U, Alignment>&) noexcept
  {
  }
  T* allocate(std::size_t n)
  {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(Alignment)));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t(Alignment)); }
  template <typename U>
  bool operator==(const AlignedAllocator<U, Alignment>&) const noexcept
  {
    return true;
  }
  template <typename U>
  bool operator!=(const AlignedAllocator<U, Alignment>&) const noexcept
  {
    return false;
  }
};

/// A vector of T aligned on 64 bytes.
template <typename T>
using AlignedVector = std::vector<T, AlignedAllocator<T, 64>>;

}  // namespace core
}  // namespace map_aided_fusion
