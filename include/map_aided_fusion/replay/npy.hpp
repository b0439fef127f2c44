/**
 * @file npy.hpp
 * @brief A NumPy `.npy` writer (format 1.0) for the snapshots `scripts/figures.py` reads.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace map_aided_fusion {
namespace replay {

/// The `.npy` header of an array of @p shape with dtype @p descr (e.g. "|i1", "<f4"), padded to 64 bytes.
std::string npyHeader(const std::vector<std::size_t>& shape, const char* descr);

/**
 * @brief Writes the C-ordered array @p data of @p shape to @p path.
 * @throws std::runtime_error when the file cannot be written
 */
template <typename T>
void writeNpy(const std::filesystem::path& path, const T* data, const std::vector<std::size_t>& shape,
              const char* descr)
{
  std::size_t n = 1;
  for (std::size_t s : shape) n *= s;
  const std::string header = npyHeader(shape, descr);
  std::ofstream f(path, std::ios::binary);
  f.write(header.data(), static_cast<std::streamsize>(header.size()));
  f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(n * sizeof(T)));
  if (!f) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace replay
}  // namespace map_aided_fusion
