// SplitTree: bins are unions of whole subtrees, the top is closed under
// taking parents, and the reported weights and critical path are those of
// the returned assignment; on trees where the best split is known by hand
// it is found, and trees that cannot be split (a chain) are left whole.

#include "ceres_sesync/internal/tree_split.h"

#include <algorithm>
#include <random>
#include <vector>

#include "gtest/gtest.h"

namespace ceres_sesync::internal {
namespace {

// Checks the invariants of `split` and returns its critical path.
double CheckSplit(const std::vector<int>& parent,
                  const std::vector<double>& weight, int num_bins,
                  const TreeSplit& split) {
  const int n = static_cast<int>(parent.size());
  double total = 0;
  for (double w : weight) total += w;
  EXPECT_DOUBLE_EQ(split.total_weight, total);
  if (split.bin.empty()) {
    EXPECT_DOUBLE_EQ(split.top_weight, total);
    return total;
  }
  std::vector<double> load(num_bins, 0.0);
  double top = 0;
  for (int s = 0; s < n; ++s) {
    const int b = split.bin[s];
    EXPECT_GE(b, -1);
    EXPECT_LT(b, num_bins);
    if (b == -1) {
      top += weight[s];
      // The top's parents are top.
      if (parent[s] >= 0) {
        EXPECT_EQ(split.bin[parent[s]], -1) << s;
      }
    } else {
      load[b] += weight[s];
      // A bin node's parent is in its bin or in the top.
      if (parent[s] >= 0) {
        EXPECT_TRUE(split.bin[parent[s]] == b || split.bin[parent[s]] == -1);
      }
    }
  }
  EXPECT_DOUBLE_EQ(split.top_weight, top);
  EXPECT_DOUBLE_EQ(split.heaviest_bin,
                   *std::max_element(load.begin(), load.end()));
  return top + split.heaviest_bin;
}

TEST(SplitTree, BalancedBinaryTreeSplitsBelowTheRoot) {
  // Complete binary tree of depth 10 in postorder, unit weights: the root
  // alone is the top, each bin one half (critical path 1 + 1023).
  std::vector<int> parent;
  // Postorder construction: node ids assigned on exit.
  auto build = [&](auto&& self, int depth) -> int {
    int left = -1, right = -1;
    if (depth > 0) {
      left = self(self, depth - 1);
      right = self(self, depth - 1);
    }
    const int id = static_cast<int>(parent.size());
    parent.push_back(-1);
    if (left >= 0) parent[left] = id;
    if (right >= 0) parent[right] = id;
    return id;
  };
  build(build, 10);
  const std::vector<double> weight(parent.size(), 1.0);
  const TreeSplit split = SplitTree(parent, weight, 2, 0.8);
  ASSERT_FALSE(split.bin.empty());
  EXPECT_DOUBLE_EQ(CheckSplit(parent, weight, 2, split), 1 + 1023);
  EXPECT_EQ(split.bin.back(), -1);
}

TEST(SplitTree, ChainIsNotSplit) {
  std::vector<int> parent(100);
  for (int s = 0; s < 100; ++s) parent[s] = s + 1 < 100 ? s + 1 : -1;
  const std::vector<double> weight(100, 1.0);
  const TreeSplit split = SplitTree(parent, weight, 2, 0.8);
  EXPECT_TRUE(split.bin.empty());
  CheckSplit(parent, weight, 2, split);
}

TEST(SplitTree, RandomForestsKeepTheInvariantsAndAreDeterministic) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 400);
    std::vector<int> parent(n);
    std::vector<double> weight(n);
    for (int s = 0; s < n; ++s) {
      // Mostly near parents (deep trees), some roots (forests).
      parent[s] = s + 1 < n && rng() % 20 != 0
                      ? s + 1 + static_cast<int>(rng() % std::min(n - s - 1, 5))
                      : -1;
      weight[s] = 1 + rng() % 100;
    }
    for (int bins : {1, 2, 3}) {
      const TreeSplit split = SplitTree(parent, weight, bins, 0.9);
      const double path = CheckSplit(parent, weight, bins, split);
      EXPECT_LE(path, split.total_weight);
      if (!split.bin.empty()) {
        EXPECT_LE(path, 0.9 * split.total_weight);
      }
      const TreeSplit again = SplitTree(parent, weight, bins, 0.9);
      EXPECT_EQ(again.bin, split.bin);
    }
  }
}

}  // namespace
}  // namespace ceres_sesync::internal
