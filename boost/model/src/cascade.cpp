// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/cascade.h"

#include <cmath>
#include <stdexcept>

namespace fusedet::boosting {

std::size_t Cascade::weakCount() const {
  std::size_t n = 0;
  for (const Stage& s : stages) n += s.stumps.size();
  for (const auto& t : treeStages) n += t.size();
  return n;
}

bool Cascade::hasTrees() const { return !treeStages.empty(); }

void requireStackNetwork(const Cascade& c, const LayerStack& stack) {
  if (!usesNetworkLayers(c.layers)) return;
  requireSameNetwork(c.network, (c.source.empty() ? "the model" : c.source) + " (class '" + c.className + "')",
                     stack.network, "the stack '" + stack.source + "'");
}

Cascade firstStages(Cascade cascade, std::size_t stages) {
  if (stages == 0) throw std::invalid_argument("firstStages: a cascade keeps at least one stage");
  if (cascade.stages.size() > stages) cascade.stages.resize(stages);
  if (cascade.treeStages.size() > stages) cascade.treeStages.resize(stages);
  return cascade;
}

int Cascade::addFeature(const Feature& f) {
  features.push_back(f);
  return static_cast<int>(features.size()) - 1;
}

void Cascade::validate() const {
  const std::string where = (source.empty() ? std::string("model") : source) + ": ";
  auto fail = [&](const std::string& what) { throw std::invalid_argument(where + what); };
  if (windowWidth <= 0 || windowHeight <= 0) fail("window size must be positive");
  if (stages.empty()) fail("cascade has no stages");
  if (layers.empty()) fail("cascade names no layers");
  if (isOpenCv()) {
    if (layers.size() != 1) fail("an OpenCV cascade reads exactly one layer");
    if (!features.empty()) fail("an OpenCV cascade cannot hold unit-square features");
  } else if (!haarFeatures.empty()) {
    fail("pixel (OpenCV) features need OpenCV variance normalisation");
  }
  for (const std::string& l : layers)
    if (l == "hue_distance" && !referenceHue) fail("layer hue_distance needs a reference hue");
  if (referenceHue && !std::isfinite(*referenceHue)) fail("reference hue is not finite");
  const std::size_t nFeatures = isOpenCv() ? haarFeatures.size() : features.size();
  for (std::size_t i = 0; i < features.size(); ++i) {
    try {
      validateFeature(features[i], layers.size());
    } catch (const std::invalid_argument& e) {
      fail("feature " + std::to_string(i) + ": " + e.what());
    }
  }
  for (std::size_t i = 0; i < haarFeatures.size(); ++i) {
    const HaarFeature& h = haarFeatures[i];
    if (h.count < 2 || h.count > 3) fail("feature " + std::to_string(i) + " has " + std::to_string(h.count) + " rectangles, expected 2 or 3");
    for (int r = 0; r < h.count; ++r) {
      const HaarRect& q = h.rects[static_cast<std::size_t>(r)];
      // 64-bit: imported numbers may be large; the sums must not overflow.
      const long long x = q.x, y = q.y, w = q.w, hh = q.h, W = windowWidth, H = windowHeight;
      bool inside;
      if (!h.tilted) {
        inside = x >= 0 && y >= 0 && w > 0 && hh > 0 && x + w <= W && y + hh <= H;
      } else {  // corners: top (x, y), right (x + w, y + w), left (x - h, y + h), bottom (x + w - h, y + w + h)
        inside = w > 0 && hh > 0 && y >= 0 && x - hh >= 0 && x + w <= W && y + w + hh <= H;
      }
      if (!inside) fail("feature " + std::to_string(i) + " rectangle " + std::to_string(r) + " lies outside the " +
                        std::to_string(windowWidth) + "x" + std::to_string(windowHeight) + " window");
      if (!std::isfinite(q.weight)) fail("feature " + std::to_string(i) + " has a non-finite weight");
    }
  }
  const bool trees = hasTrees();
  if (trees && !isOpenCv()) fail("decision trees are only supported in imported OpenCV cascades");
  if (trees && treeStages.size() != stages.size())
    fail("tree cascade has " + std::to_string(treeStages.size()) + " tree stages for " + std::to_string(stages.size()) +
         " stages");
  for (std::size_t s = 0; s < stages.size(); ++s) {
    const Stage& st = stages[s];
    const std::string at = "stage " + std::to_string(s);
    const std::vector<Tree> noTrees;
    const std::vector<Tree>& stTrees = trees ? treeStages[s] : noTrees;
    if (st.stumps.empty() && stTrees.empty()) fail(at + " has no weak classifiers");
    if (trees && !st.stumps.empty()) fail(at + " mixes stumps and trees");
    if (!std::isfinite(st.threshold)) fail(at + " threshold is not finite");
    auto checkFeature = [&](int feature, const std::string& atk) {
      if (feature < 0 || static_cast<std::size_t>(feature) >= nFeatures)
        fail(atk + ": feature index " + std::to_string(feature) + " out of range (model has " +
             std::to_string(nFeatures) + " features)");
    };
    for (std::size_t k = 0; k < st.stumps.size(); ++k) {
      const Stump& t = st.stumps[k];
      const std::string atk = at + " weak classifier " + std::to_string(k);
      checkFeature(t.feature, atk);
      if (!std::isfinite(t.threshold)) fail(atk + ": threshold is not finite");
      if (!std::isfinite(t.left) || !std::isfinite(t.right)) fail(atk + ": leaf value is not finite");
    }
    for (std::size_t k = 0; k < stTrees.size(); ++k) {
      const Tree& t = stTrees[k];
      const std::string atk = at + " weak classifier " + std::to_string(k);
      if (t.nodes.empty()) fail(atk + ": tree without nodes");
      if (t.leaves.size() != t.nodes.size() + 1) fail(atk + ": tree needs nodes + 1 leaves");
      for (double v : t.leaves)
        if (!std::isfinite(v)) fail(atk + ": leaf value is not finite");
      for (std::size_t n = 0; n < t.nodes.size(); ++n) {
        const TreeNode& node = t.nodes[n];
        checkFeature(node.feature, atk);
        if (!std::isfinite(node.threshold)) fail(atk + ": threshold is not finite");
        for (int child : {node.left, node.right}) {
          // Children after their parent: evaluation always terminates.
          const bool okNode = child > 0 && static_cast<std::size_t>(child) > n && static_cast<std::size_t>(child) < t.nodes.size();
          const bool okLeaf = child <= 0 && static_cast<std::size_t>(-static_cast<long long>(child)) < t.leaves.size();
          if (!okNode && !okLeaf)
            fail(atk + ": node " + std::to_string(n) + " has child " + std::to_string(child) +
                 " (must be a later node or a leaf)");
        }
      }
    }
  }
}

}  // namespace fusedet::boosting
