// A split of an elimination tree for two-level parallelism: whole subtrees
// go to `num_bins` bins, which can be processed concurrently, and their
// common ancestors form the "top", processed after (forward) or before
// (backward) them. Used by the parallel triangular solves of
// SparseCholeskyFactor and the parallel double-double factorization.

#ifndef CERES_SESYNC_INTERNAL_TREE_SPLIT_H_
#define CERES_SESYNC_INTERNAL_TREE_SPLIT_H_

#include <vector>

namespace ceres_sesync::internal {

// Bins of the splits used by the library: two, the cores of the machines it
// is measured on. Fixed (never the thread count), so that the schedules, and
// the results computed with them, are the same for every thread count.
constexpr int kTreeSplitBins = 2;

struct TreeSplit {
  // bin[s] in 0 .. num_bins - 1, or -1 for the top. Empty if not split.
  std::vector<int> bin;
  double top_weight = 0;  // Weight of the top (all of it if not split).
  double heaviest_bin = 0;
  double total_weight = 0;
};

// Nodes s = 0 .. parent.size() - 1 with parent[s] > s (or -1 for a root) and
// nonnegative weights. The top is grown from the roots by always moving the
// heaviest subtree of the frontier into it; of the first `max_top_nodes`
// such prefixes the one with the shortest critical path (top + heaviest bin,
// the frontier subtrees put into bins heaviest first, each into the lightest
// bin) is kept, if that path is at most max_critical_fraction of the total
// weight (else no split). Deterministic: depends on the tree and weights
// only.
TreeSplit SplitTree(const std::vector<int>& parent,
                    const std::vector<double>& weight, int num_bins,
                    double max_critical_fraction, int max_top_nodes = 4096);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_TREE_SPLIT_H_
