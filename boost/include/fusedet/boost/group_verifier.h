#pragma once
// Learned group verifier: a grouped detection's score from what the detector knows about it,
// instead of its neighbour count alone.
//
// Why: car's misses at its own settings are mostly groups with fewer than 16 member windows
// ("too few neighbours"); keeping smaller groups added about as many false alarms as cars, because
// the member count was the only score a group had. The verifier scores every group kept at a LOW
// neighbour floor from its members (count, box spread, cascade margins) and from PHYSICAL cues of
// the laser: the box's distance, its pixel height x distance (proportional to metric height for
// one camera), the share of measured laser cells, the distance spread inside the box and, when the
// stack has one, the `height` layer (metres above the fitted ground plane).
//
// Features (groupFeatures(), groupFeatureCount() numbers, all finite):
//   boxFeatures() of box_regression.h (31: group/member edges, log(1 + members), laser-extent
//   edges, laser rows, aspect, height, position); the members' last-stage sums (mean, max, min);
//   from the distance layer's cells in the box's core (laser_cells.h: rows 35-85 % of its height,
//   middle half of its columns): whether at least 6 are measured, their share of the band's cells, log median
//   distance, their interquartile range / median, log(pixel height x median distance), log(pixel
//   width x median distance); from the `height` layer's measured cells in the box: whether any,
//   the 90th percentile (the object's top above the ground), the 10th percentile of its bottom
//   fifth (where it stands); the squares of log(pixel height x distance) and of that 90th
//   percentile (0 without the layer), so that a linear score can prefer a range.
//   No focal length: the stack carries no intrinsics, so "pixel height x distance" is in px m
//   (metric height x focal); a verifier is fitted per camera (per fold here), which absorbs the
//   constant. A verifier stored for another camera would need the focal length too.
//
// Kinds (VerifierParams::kind):
//   kLogistic: L2-regularised logistic regression on standardised features, unpenalised intercept,
//     Newton's method (Eigen LDLT). Labels: a training detection that hits a positive label under
//     the evaluation's matching rule (1) against one scored a false alarm (0; ignored ones are left
//     out). A detection's score becomes the fitted probability; groups below the operating
//     threshold - the one with the highest F on the TRAINING detections (2 hits / (detections +
//     positives)) - are dropped.
//   kHeightGate (a non-learned baseline): the range [gateLow, gateHigh] percentiles of the training
//     HITS' pixel height x distance; a group with laser cells outside it is dropped, its score stays.
// Degenerate input has a defined outcome: fewer than minSamples usable samples, no hit or no false
// alarm (one class only), or no features -> no fit (`why` says so), and an unfitted verifier keeps
// every detection with its score (identity). A feature constant over the samples gets weight 0;
// separable data stays finite (the L2 term); a sample with a non-finite value is left out.

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fusedet/boost/box_regression.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

// fusion's height-above-ground layer (fusion/channel_layers.h), read by name: boost/ does not
// include fusion.
inline constexpr std::string_view kHeightLayerName = "height";

std::vector<double> groupFeatures(const GroupedBox& g, const LayerStack& stack);
std::size_t groupFeatureCount();
// Index in groupFeatures() of log(pixel height x median distance), and of the flag that the laser
// saw the box (the gate's measurement).
std::size_t pixelMetreHeightIndex();
std::size_t laserSeenIndex();

struct VerifierParams {
  enum class Kind { kLogistic, kHeightGate };
  Kind kind = Kind::kLogistic;
  double lambda = 1;            // L2 penalty on standardised features (> 0)
  std::size_t minSamples = 20;  // usable samples needed
  int maxIterations = 50;       // Newton steps
  double gateLow = 0.02, gateHigh = 0.98;  // kHeightGate: percentiles of the hits' height
  // kLogistic: which features it weighs (the others get weight 0): every one, the compact set
  // (members, aspect, height, cascade margins, laser and height cues) or the physical set (members,
  // laser and height cues with the squares that let a linear score express a range);
  // featureSet().
  enum class Features { kAll, kCompact, kPhysical };
  Features features = Features::kAll;
  // > 0: a training detection is a hit (label 1) when it overlaps a positive label by this IoU,
  // instead of the evaluation's rule (e.g. 0.5: a car placed loosely is still a car).
  double labelIou = 0;
  // kLogistic: the kept groups' score becomes the probability (true) or stays the group's (false:
  // the verifier only filters).
  bool rescore = true;
};

// The indices of a feature set in groupFeatures().
std::vector<std::size_t> featureSet(VerifierParams::Features set);

// A fitted verifier; default-constructed = no fit (keeps every detection, scores unchanged).
struct GroupVerifier {
  VerifierParams::Kind kind = VerifierParams::Kind::kLogistic;
  std::vector<double> mean, scale, weights;  // kLogistic: standardisation and weights per feature
  double intercept = 0;
  double threshold = 0;                      // kLogistic: keep probability >= threshold
  double gateLow = 0, gateHigh = 0;          // kHeightGate: log(pixel height x distance) range
  double lambda = 0;
  std::size_t samples = 0, hits = 0;         // usable samples, of them hits
  double trainingF = 0;                      // kLogistic: F on the training detections at threshold
  bool rescore = true;                       // kLogistic: VerifierParams::rescore
  bool ready = false;
  std::string why;  // when not fitted: why not

  bool fitted() const { return ready; }
  // kLogistic: the probability of a hit (0.5 when not fitted).
  double probability(std::span<const double> features) const;
  // Whether a group with these features is kept, and its score (`groupScore` when the verifier
  // does not rescore).
  bool accepts(std::span<const double> features) const;
  double score(std::span<const double> features, double groupScore) const;
};

// Fits on features[i] with label isHit[i]; `positives` = positive labels on the training frames
// (hit or missed: the F the threshold maximises counts the misses too). Throws
// std::invalid_argument when lambda <= 0, the two differ in number or rows differ in length.
GroupVerifier fitGroupVerifier(const std::vector<std::vector<double>>& features, const std::vector<bool>& isHit,
                               std::size_t positives, const VerifierParams& params);

// Applies `verifier` to grouped detections (groups[i] formed detections[i]): rejected ones are
// removed, kept ones rescored, order kept; fates (grouping.h) are renumbered, a rejected group's
// members count as kTooFewNeighbours (its support too weak). Nothing changes when not fitted.
void verifyGroups(std::vector<Detection>& detections, const std::vector<GroupedBox>& groups,
                  std::vector<std::vector<HitFate>>& fates, const LayerStack& stack, const GroupVerifier& verifier);

}  // namespace fusedet::boosting
