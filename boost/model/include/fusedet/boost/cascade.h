// SPDX-License-Identifier: Apache-2.0
#pragma once
// Cascade: the in-memory model every part of boost/ shares - trained by training (model_io.h
// reads and writes it), imported from OpenCV Haar XML (opencv_cascade.h), run by detector.h.
//
// A cascade is a list of stages; a stage is a list of regression stumps plus a threshold.
// Stump: f(value) = value < threshold ? left : right. Stage: passes when the sum of its stumps is
// >= its threshold (OpenCV rejects when sum < threshold, so both agree). A window is accepted
// when it passes every stage; its score is the sum of the last stage.
//
// Two kinds of features, two clearly separated evaluation paths:
//  - our models (Normalization::kNone): `features` are paper features a-j in unit-square window
//    coordinates on any layer (feature.h); windows scan the layer stack directly;
//  - imported OpenCV models (Normalization::kOpenCvVariance): `haarFeatures` are weighted
//    rectangles in the base window's pixels (upright or 45° tilted), evaluated on OpenCV's image
//    pyramid of one 8-bit layer with its variance normalisation, for bit-exact parity.
// Stumps index into the vector the model's kind uses.

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/boost/feature.h"
#include "fusedet/core/layer_stack.h"
#include "fusedet/core/network_record.h"

namespace fusedet::boosting {

enum class Normalization {
  kNone,            // feature value as is (our models)
  kOpenCvVariance,  // OpenCV: value / (window stddev * area), on an image pyramid of one layer
};

struct Stump {
  int feature = 0;       // index into Cascade::features or Cascade::haarFeatures
  double threshold = 0;  // value < threshold -> left, else right (compared in float)
  double left = 0, right = 0;
};

// A decision tree, only in imported OpenCV cascades whose weak classifiers split more than once
// (alt2, *_2splits, eye_tree_eyeglasses). From node 0: value < threshold ? left : right; a child
// > 0 is a node index (always greater than its parent's), a child <= 0 is the leaf -child.
struct TreeNode {
  int feature = 0;  // index into Cascade::haarFeatures
  double threshold = 0;
  int left = 0, right = 0;
};
struct Tree {
  std::vector<TreeNode> nodes;
  std::vector<double> leaves;  // nodes.size() + 1
};

struct Stage {
  std::vector<Stump> stumps;
  double threshold = 0;  // stage passes when sum of its weak classifiers' outputs >= threshold
};

// OpenCV Haar feature: up to three weighted rectangles in base-window pixels. Tilted rectangles
// are rotated by 45°: (x, y) is the top corner, w runs down-right and h down-left.
struct HaarRect {
  int x = 0, y = 0, w = 0, h = 0;
  float weight = 0;
};
struct HaarFeature {
  std::array<HaarRect, 3> rects{};
  int count = 0;
  bool tilted = false;
};

struct Cascade {
  std::string className;                // "car", "person", ... or the imported file's stem
  int windowWidth = 24, windowHeight = 24;  // base window in pixels (aspect ratio = w / h)
  std::vector<std::string> layers;          // layer names the features index
  std::optional<double> referenceHue;       // degrees, for a "hue_distance" layer
  NetworkRecord network;                    // the network that made its neural_* layers (empty: none)
  Normalization normalization = Normalization::kNone;
  std::vector<Feature> features;          // kNone
  std::vector<HaarFeature> haarFeatures;  // kOpenCvVariance
  std::vector<Stage> stages;
  // OpenCV tree cascades only: the weak classifiers of stage i are treeStages[i] (instead of
  // stages[i].stumps, which stay empty; stages[i].threshold applies). Empty for every other model.
  std::vector<std::vector<Tree>> treeStages;
  std::string source;  // file the model came from (for messages), may be empty

  double aspectRatio() const { return double(windowWidth) / double(windowHeight); }
  bool isOpenCv() const { return normalization == Normalization::kOpenCvVariance; }
  bool hasTrees() const;
  std::size_t weakCount() const;  // stumps + trees
  // Adds a feature (our kind) and returns its index for Stump::feature.
  int addFeature(const Feature& f);

  // Throws std::invalid_argument naming `source` and the first problem: no stages, empty stage,
  // feature index out of range, non-finite threshold or leaf, rectangle outside the window, layer
  // index out of range, hue_distance without a reference hue, OpenCV model without one layer,
  // trees in one of our models, a tree stage count other than the stage count, a stage mixing
  // stumps and trees, a tree whose children do not follow their parent.
  void validate() const;
};

// A cascade that uses neural_* layers needs a stack whose network (LayerStack::network) is the one
// it was trained on; throws std::runtime_error naming the model, the stack and both networks
// (fusedet/core/network_record.h requireSameNetwork). Nothing for a cascade without such layers.
void requireStackNetwork(const Cascade& cascade, const LayerStack& stack);

// The cascade's first `stages` stages (all of them when it has no more). Training adds stages in
// order, each from the cascade before it with its own per-stage seed (cascade_trainer.h), so this
// is the cascade training with max_stages = `stages` gives: a stage-count sweep can cut trained
// models instead of training again. Throws std::invalid_argument for 0.
Cascade firstStages(Cascade cascade, std::size_t stages);

}  // namespace fusedet::boosting
