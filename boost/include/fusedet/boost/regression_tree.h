#pragma once
// The weak learner for tree cascades: a regression tree of depth d (CART) fitted by weighted least
// squares on labels y = +1 (positives) / -1 (negatives), greedily node by node - each node's split
// is the stump search of stump.h (binned histograms, then exact refinement of the best few) on that
// node's samples only (LightGBM/XGBoost "hist" style: a node's histograms are built from its own
// samples, so each level of the tree costs one pass over the samples). A leaf's value is its
// samples' weighted mean label, as a stump's leaves. Depth 1 is exactly findBestStump()'s stump.
// Dollar et al.'s ACF detectors use depth-2 trees for the same reason: one split cannot express
// "feature A high AND feature B low" within one weak learner.
//
// A node becomes a leaf when it is at the depth limit, holds samples of one class only or no split
// lowers its squared error (the root always splits, as a stump does, possibly with no gain).
// Ties as in stump.h (smaller feature, then smaller threshold): deterministic for any thread count.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/feature_matrix.h"
#include "fusedet/boost/stump.h"

namespace fusedet::boosting {

// Nodes in pre-order (children after their parent); a child > 0 is a node index, <= 0 the leaf
// -child (cascade.h's Tree convention); feature = row of the matrix.
struct FittedTree {
  struct Node {
    std::size_t feature = 0;
    float threshold = 0;  // value < threshold -> left
    int left = 0, right = 0;
  };
  std::vector<Node> nodes;
  std::vector<double> leaves;  // nodes.size() + 1
  double error = 0;            // weighted squared error sum_i w_i (y_i - f(x_i))^2 on the training samples

  // f(x) from the values of the nodes' features: value(k) = the value of nodes[k].feature.
  template <class NodeValue>
  double operator()(NodeValue&& value) const {
    int n = 0;
    for (;;) {
      const Node& node = nodes[static_cast<std::size_t>(n)];
      const int child = value(static_cast<std::size_t>(n)) < node.threshold ? node.left : node.right;
      if (child <= 0) return leaves[static_cast<std::size_t>(-child)];
      n = child;
    }
  }
};

struct TreeSearchOptions {
  int depth = 2;  // >= 1; 1 = a stump
  StumpSearchOptions stump;
};

// Fits the tree for `weights` (samples [0, positives) positives) and writes f(x_i) of every sample
// to `outputs`. rawValues: a matrix row's raw values (as for findBestStump()). Throws
// std::invalid_argument on mismatched sizes, an empty matrix or depth < 1.
FittedTree fitRegressionTree(const FeatureMatrix& m, std::size_t positives, std::span<const float> weights,
                             const FeatureValuesFn& rawValues, const TreeSearchOptions& options,
                             std::span<double> outputs);

// The cascade's form of a fitted tree: features mapped by `featureIndex` (matrix row -> index
// into Cascade::features).
template <class FeatureIndex>
Tree toCascadeTree(const FittedTree& t, FeatureIndex&& featureIndex) {
  Tree out;
  for (const FittedTree::Node& n : t.nodes)
    out.nodes.push_back(TreeNode{featureIndex(n.feature), double(n.threshold), n.left, n.right});
  out.leaves = t.leaves;
  return out;
}

}  // namespace fusedet::boosting
