// Rank and order questions about millions of values, without sorting them all (internal header).
#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

namespace partet {

// Values that answer "how many lie below x" and "the r-th smallest" as a sorted copy would,
// without sorting them all (the balancing asks a few dozen questions of millions of values): one
// pass puts them in buckets of equal width, and a bucket is sorted when a question first needs it.
class RankedValues {
 public:
  explicit RankedValues(const std::vector<double>& values) : size_(values.size()) {
    if (values.empty()) return;
    const auto [low, high] = std::minmax_element(values.begin(), values.end());
    low_ = *low;
    const std::size_t buckets = std::clamp<std::size_t>(values.size() / 2048, 1, 4096);
    scale_ = *high > *low ? static_cast<double>(buckets) / (*high - *low) : 0;
    start_.assign(buckets + 1, 0);
    for (double x : values) ++start_[bucket_of(x) + 1];
    for (std::size_t b = 0; b < buckets; ++b) start_[b + 1] += start_[b];
    std::vector<std::size_t> next(start_.begin(), start_.end() - 1);
    grouped_.resize(values.size());
    for (double x : values) grouped_[next[bucket_of(x)]++] = x;
    sorted_.assign(buckets, 0);
  }
  std::size_t size() const { return size_; }
  std::size_t count_below(double x) const {
    if (size_ == 0) return 0;
    const std::size_t b = bucket_of(x);
    const auto* first = sorted_bucket(b);
    const double* last = grouped_.data() + start_[b + 1];
    return start_[b] + static_cast<std::size_t>(std::lower_bound(first, last, x) - first);
  }
  double at(std::size_t r) const {  // r < size()
    const std::size_t b =
        static_cast<std::size_t>(std::upper_bound(start_.begin(), start_.end(), r) - start_.begin()) - 1;
    return sorted_bucket(b)[r - start_[b]];
  }

 private:
  // Never decreasing in x, so every value of a bucket is below every value of a later one.
  std::size_t bucket_of(double x) const {
    if (!(x > low_)) return 0;
    const double at = (x - low_) * scale_;  // may be infinite when the values span a tiny range
    const std::size_t last = start_.size() - 2;
    return at < static_cast<double>(last) ? static_cast<std::size_t>(at) : last;
  }
  const double* sorted_bucket(std::size_t b) const {
    double* first = grouped_.data() + start_[b];
    if (!sorted_[b]) std::sort(first, grouped_.data() + start_[b + 1]), sorted_[b] = 1;
    return first;
  }
  std::size_t size_;
  double low_ = 0, scale_ = 0;
  std::vector<std::size_t> start_;  // bucket b holds grouped_[start_[b], start_[b + 1])
  mutable std::vector<double> grouped_;
  mutable std::vector<char> sorted_;
};

}  // namespace partet
