#include "fusedet/boost/regression_tree.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace fusedet::boosting {

namespace {

class TreeFitter {
 public:
  TreeFitter(const FeatureMatrix& m, std::size_t positives, std::span<const float> weights,
             const FeatureValuesFn& rawValues, const TreeSearchOptions& options, std::span<double> outputs)
      : m_(m), positives_(positives), weights_(weights), raw_(rawValues), options_(options), outputs_(outputs),
        values_(m.samples()) {}

  FittedTree fit() {
    std::vector<std::uint32_t> all(m_.samples());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
    grow(all, 0);
    return std::move(tree_);
  }

 private:
  // Adds the subtree of `samples` at `depth`: returns its reference (node index > 0, or -leaf).
  int grow(const std::vector<std::uint32_t>& samples, int depth) {
    const bool root = depth == 0;
    std::vector<float> w(samples.size());
    std::size_t pos = 0;
    double tot = 0, totS = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      w[i] = weights_[samples[i]];
      const bool positive = samples[i] < positives_;
      pos += positive;
      tot += w[i];
      totS += positive ? w[i] : -double(w[i]);
    }
    const bool pure = pos == 0 || pos == samples.size();
    if (!root && (depth >= options_.depth || pure || samples.size() < 2)) return leaf(samples, tot > 0 ? totS / tot : 0);
    // The node's best split: binned candidates on its samples, refined exactly on them.
    const std::vector<SplitCandidate> candidates =
        root ? bestBinnedSplits(m_, positives_, weights_, options_.stump.refineTop, options_.stump.threads)
             : bestBinnedSplits(m_, samples, pos, w, options_.stump.refineTop, options_.stump.threads);
    FittedStump best;
    std::vector<float> nodeValues(samples.size()), bestValues;
    bool have = false;
    for (std::size_t f : refineOrder(candidates)) {
      raw_(f, values_);
      for (std::size_t i = 0; i < samples.size(); ++i) nodeValues[i] = values_[samples[i]];
      const FittedStump s = fitStumpExact(f, nodeValues, w, pos);
      if (!have || s.error < best.error) {
        best = s;
        bestValues = nodeValues;
        have = true;
      }
    }
    const bool split = std::isfinite(best.threshold);
    if (!root && !split) return leaf(samples, tot > 0 ? totS / tot : 0);
    const int index = static_cast<int>(tree_.nodes.size());
    tree_.nodes.push_back(FittedTree::Node{best.feature, best.threshold, 0, 0});
    if (depth + 1 >= options_.depth || !split) {  // children are leaves: the stump's leaf values
      for (std::size_t i = 0; i < samples.size(); ++i) outputs_[samples[i]] = best(bestValues[i]);
      tree_.nodes[static_cast<std::size_t>(index)].left = addLeaf(best.left);
      tree_.nodes[static_cast<std::size_t>(index)].right = addLeaf(best.right);
      return index;
    }
    std::vector<std::uint32_t> left, right;
    for (std::size_t i = 0; i < samples.size(); ++i) (bestValues[i] < best.threshold ? left : right).push_back(samples[i]);
    const int l = grow(left, depth + 1);
    tree_.nodes[static_cast<std::size_t>(index)].left = l;
    const int r = grow(right, depth + 1);
    tree_.nodes[static_cast<std::size_t>(index)].right = r;
    return index;
  }

  int addLeaf(double v) {
    tree_.leaves.push_back(v);
    return -static_cast<int>(tree_.leaves.size() - 1);
  }
  int leaf(const std::vector<std::uint32_t>& samples, double v) {
    for (std::uint32_t i : samples) outputs_[i] = v;
    return addLeaf(v);
  }

  const FeatureMatrix& m_;
  std::size_t positives_;
  std::span<const float> weights_;
  const FeatureValuesFn& raw_;
  const TreeSearchOptions& options_;
  std::span<double> outputs_;
  std::vector<float> values_;
  FittedTree tree_;
};

}  // namespace

FittedTree fitRegressionTree(const FeatureMatrix& m, std::size_t positives, std::span<const float> weights,
                             const FeatureValuesFn& rawValues, const TreeSearchOptions& options,
                             std::span<double> outputs) {
  const std::size_t n = m.samples();
  if (m.features() == 0 || n == 0) throw std::invalid_argument("fitRegressionTree: empty feature matrix");
  if (weights.size() != n || outputs.size() != n || positives > n)
    throw std::invalid_argument("fitRegressionTree: " + std::to_string(weights.size()) + " weights, " +
                                std::to_string(outputs.size()) + " outputs, " + std::to_string(positives) +
                                " positives for " + std::to_string(n) + " samples");
  if (options.depth < 1) throw std::invalid_argument("fitRegressionTree: depth must be >= 1");
  FittedTree t = TreeFitter(m, positives, weights, rawValues, options, outputs).fit();
  double e = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = (i < positives ? 1.0 : -1.0) - outputs[i];
    e += double(weights[i]) * d * d;
  }
  t.error = e;
  return t;
}

}  // namespace fusedet::boosting
