#pragma once

// Disjoint sets over 0..n-1 (union by smaller index, path halving): groups of
// linked elements, e.g. regions of similar planes or photos that share
// points. Each set's root is its smallest element, so that roots, and what
// is numbered by them, do not depend on the order of the unions.

#include <algorithm>
#include <numeric>
#include <vector>

namespace casual3d::util {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  // The root (smallest element) of a's set.
  int Find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  // Joins the sets of a and b.
  void Union(int a, int b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace casual3d::util
