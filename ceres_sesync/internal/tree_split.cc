#include "ceres_sesync/internal/tree_split.h"

#include <algorithm>
#include <functional>
#include <numeric>
#include <set>
#include <utility>

#include "glog/logging.h"

namespace ceres_sesync::internal {

TreeSplit SplitTree(const std::vector<int>& parent,
                    const std::vector<double>& weight, int num_bins,
                    double max_critical_fraction, int max_top_nodes) {
  const int n = static_cast<int>(parent.size());
  CHECK_EQ(static_cast<int>(weight.size()), n);
  CHECK_GE(num_bins, 1);
  TreeSplit split;
  std::vector<double> subtree = weight;
  std::vector<int> child_start(n + 1, 0);
  for (int s = 0; s < n; ++s) {
    if (parent[s] < 0) continue;
    CHECK_GT(parent[s], s);
    CHECK_LT(parent[s], n);
    subtree[parent[s]] += subtree[s];
    ++child_start[parent[s] + 1];
  }
  std::partial_sum(child_start.begin(), child_start.end(), child_start.begin());
  std::vector<int> children(n),
      next(child_start.begin(), child_start.end() - 1);
  // (weight, node), heaviest first; ties by the larger node: deterministic.
  std::set<std::pair<double, int>, std::greater<>> frontier;
  for (int s = 0; s < n; ++s) {
    if (parent[s] < 0) {
      frontier.emplace(subtree[s], s);
      split.total_weight += subtree[s];
    } else {
      children[next[parent[s]]++] = s;
    }
  }
  const double total = split.total_weight;
  std::vector<double> load(num_bins);
  auto fill_bins = [&](std::vector<int>* bin) {
    std::fill(load.begin(), load.end(), 0.0);
    for (const auto& [w, s] : frontier) {
      const int b = static_cast<int>(
          std::min_element(load.begin(), load.end()) - load.begin());
      load[b] += w;
      if (bin != nullptr) (*bin)[s] = b;
    }
    return *std::max_element(load.begin(), load.end());
  };
  std::vector<int> taken;  // The top in the order it was grown.
  double top_weight = 0, best_path = total;
  size_t best_size = 0;
  bool found = false;
  while (!frontier.empty() && top_weight < best_path &&
         static_cast<int>(taken.size()) < max_top_nodes) {
    const double path = top_weight + fill_bins(nullptr);
    if (path < best_path) {
      best_path = path;
      best_size = taken.size();
      found = true;
    }
    const int s = frontier.begin()->second;
    frontier.erase(frontier.begin());
    taken.push_back(s);
    top_weight += weight[s];
    for (int k = child_start[s]; k < child_start[s + 1]; ++k) {
      frontier.emplace(subtree[children[k]], children[k]);
    }
  }
  split.top_weight = total;
  if (!found || best_path > max_critical_fraction * total) return split;
  // The best prefix: its frontier into the bins, the rest below follows.
  std::vector<int> bin(n, -2);
  for (size_t k = 0; k < best_size; ++k) bin[taken[k]] = -1;
  frontier.clear();
  for (int s = 0; s < n; ++s) {
    const bool parent_in_top = parent[s] < 0 || bin[parent[s]] == -1;
    if (bin[s] != -1 && parent_in_top) frontier.emplace(subtree[s], s);
  }
  split.heaviest_bin = fill_bins(&bin);
  split.top_weight = 0;
  for (size_t k = 0; k < best_size; ++k) split.top_weight += weight[taken[k]];
  for (int s = n - 1; s >= 0; --s) {
    if (bin[s] == -2) bin[s] = bin[parent[s]];  // Parents come first here.
  }
  split.bin = std::move(bin);
  return split;
}

}  // namespace ceres_sesync::internal
