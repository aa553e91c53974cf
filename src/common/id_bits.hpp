// A set of ids as one bit each (internal header): for ids up to about the number of points of a
// mesh, far smaller than listing every use of each id and sorting them out.
#pragma once
#include <cstdint>
#include <vector>

namespace partet {

class IdBits {
 public:
  void insert(std::uint64_t id) {
    const auto word = static_cast<std::size_t>(id / 64);
    if (word >= words_.size()) words_.resize(word + 1, 0);
    words_[word] |= std::uint64_t{1} << (id % 64);
  }
  // The ids, ascending.
  template <class T>
  std::vector<T> ascending() const {
    std::vector<T> ids;
    for (std::size_t word = 0; word < words_.size(); ++word)
      for (std::uint64_t bits = words_[word]; bits != 0; bits &= bits - 1)
        ids.push_back(static_cast<T>(64 * word + static_cast<std::uint64_t>(__builtin_ctzll(bits))));
    return ids;
  }

 private:
  std::vector<std::uint64_t> words_;
};

}  // namespace partet
