// FNV-1a, 64-bit: a quick hash of bytes for keys whose hits are confirmed by comparing (internal
// header). Chained calls hash the concatenation: fnv1a(b, fnv1a(a)) == fnv1a(a + b).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace partet {

inline constexpr std::uint64_t kFnv1aStart = 1469598103934665603ull;

inline std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h = kFnv1aStart) {
  const auto* b = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 1099511628211ull;
  return h;
}

inline std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = kFnv1aStart) {
  return fnv1a(bytes.data(), bytes.size(), h);
}

}  // namespace partet
