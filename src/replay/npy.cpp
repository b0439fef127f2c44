#include "map_aided_fusion/replay/npy.hpp"

namespace map_aided_fusion {
namespace replay {

namespace {
constexpr std::size_t kAlignment = 64;   ///< header + data start on a multiple of this
constexpr std::size_t kPrefixBytes = 10;  ///< magic (6), version (2), header length (2)
}  // namespace

std::string npyHeader(const std::vector<std::size_t>& shape, const char* descr)
{
  std::ostringstream dict;
  dict << "{'descr': '" << descr << "', 'fortran_order': False, 'shape': (";
  for (std::size_t s : shape) dict << s << ", ";
  dict << "), }";
  std::string h = dict.str();
  const std::size_t total = kPrefixBytes + h.size() + 1;
  h.append((kAlignment - total % kAlignment) % kAlignment, ' ');
  h += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  const auto len = static_cast<std::uint16_t>(h.size());
  out += static_cast<char>(len & 0xff);
  out += static_cast<char>(len >> 8);
  return out + h;
}

}  // namespace replay
}  // namespace map_aided_fusion
