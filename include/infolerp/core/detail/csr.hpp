#pragma once
// Stable counting sort into compressed sparse rows (CSR): items 0..n-1, each with a bucket key,
// become `offsets` (bucket count + 1 entries) and `grouped`, where bucket k holds
// grouped[offsets[k] .. offsets[k + 1]), the values of its items in ascending item order.
// An item whose key is `no_bucket` is left out.
// Preconditions: every other key < bucket_count; fewer than 2^32 items. Complexity
// O(bucket_count + n), key_of called twice per item, value_of once per grouped item. Allocation:
// none beyond resizing the two outputs (the fill cursors live in `offsets`, one slot ahead), so
// buffers reused from call to call do not reallocate.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace infolerp::detail {

inline constexpr std::uint32_t no_bucket = 0xffffffffu;

template <class T, class KeyOf, class ValueOf>
void group_by_key(std::size_t bucket_count, std::size_t item_count, KeyOf key_of, ValueOf value_of,
                  std::vector<std::uint32_t>& offsets, std::vector<T>& grouped) {
  // Count bucket k at offsets[k + 2]; the prefix sum then puts bucket k's start at offsets[k + 1],
  // the fill advances it to bucket k's end, which is bucket k + 1's start: offsets[0 .. count].
  offsets.assign(bucket_count + 2, 0);
  for (std::size_t i = 0; i < item_count; ++i)
    if (const std::uint32_t k = key_of(i); k != no_bucket) ++offsets[std::size_t{k} + 2];
  for (std::size_t k = 2; k < offsets.size(); ++k) offsets[k] += offsets[k - 1];
  grouped.resize(offsets.back());
  for (std::size_t i = 0; i < item_count; ++i)
    if (const std::uint32_t k = key_of(i); k != no_bucket) grouped[offsets[std::size_t{k} + 1]++] = value_of(i);
  offsets.pop_back();
}

}  // namespace infolerp::detail
