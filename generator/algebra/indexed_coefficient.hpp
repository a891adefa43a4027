// A sparse three-index coefficient T^upper_{lower_a lower_b} with a symbolic value: the Hamel coefficients
// γ^c_ab, the structure constants c^α_βλ of a Lie algebra and the bundle coefficients (curvature B^α_IJ,
// E^α_βI) are all lists of these, kept in one order.
#pragma once

#include <ginac/ginac.h>

#include <algorithm>
#include <tuple>
#include <vector>

namespace hamel {

/// One non-zero coefficient T^upper_{lower_a lower_b}. Indices count within their own ranges (a bundle's
/// α from 0 in the group, I from 0 in the shape).
struct IndexedCoefficient {
  int upper;
  int lower_a;
  int lower_b;
  GiNaC::ex value;
};

/// Sorts by (upper, lower_a, lower_b), the order in which derive/ and lie/ return their lists.
inline void sort_by_indices(std::vector<IndexedCoefficient>& list) {
  std::sort(list.begin(), list.end(), [](const IndexedCoefficient& x, const IndexedCoefficient& y) {
    return std::tie(x.upper, x.lower_a, x.lower_b) < std::tie(y.upper, y.lower_a, y.lower_b);
  });
}

}  // namespace hamel
