// SPDX-License-Identifier: Apache-2.0
#pragma once
// Targetless laser->camera calibration: refines all 6 degrees of freedom of the extrinsics from a
// few frames of ordinary scenes by maximising the agreement between what the laser and the camera
// see, coarse to fine over an image pyramid with a derivative-free optimiser (Nelder-Mead).
// Two agreement measures, usable alone or summed:
//  - mutual information between laser remission and image intensity at the projected points,
//    one joint histogram over all frames (Pandey, McBride, Savarese, Eustice, 2012);
//  - depth edges against image edges: points where the range jumps along a scan line, weighted by
//    the jump, score the image's edge strength spread by a max-decay filter (Levinson & Thrun, 2013).
//
// Targetless: the laser points of each frame are chosen once under the start transform (in front of
// the camera, inside the image plus a 15 % margin), and points hidden in the camera's view behind
// nearer points (within 0.25 deg) are dropped: the Velodyne sits 27 cm behind the camera, so its
// background shows through foreground silhouettes. Depth edges are points nearer than a neighbour
// on a spherical azimuth x elevation grid by >= 0.3 m (any scanner pattern); each is placed half way
// between its own direction and the farther neighbour's (the silhouette lies between the two
// samples; at the sample itself every edge sat ~0.2 deg inside its object). The image's Sobel
// magnitude (99th percentile = 1) is spread by a max-decay filter, 0.8 per pixel (`edgeDecay`; the
// earlier 0.95 made a basin so wide that its peak sat 2.5-9 cm off along the camera's y and z axes,
// see the profiles in `bench/README.md`). The edge measure is the mean edge strength under depth-edge
// points minus that under the other points, so moving everything onto texture gains nothing. Mutual
// information of remission and grey is the second measure (`mi`, or `both`). The search is
// Nelder-Mead with restarts inside 6 deg / 0.4 m of the start, at full resolution by default
// (`pyramidLevels` > 1 adds coarser levels first, each with the same decay per pixel of its level,
// so coarse levels see wider edges). Uncertainty: leave-one-frame-out jackknife.
//
// Accuracy on KITTI is measured by `bench/calib_kitti_bench.cpp`: from starts 1-2 deg / 5-10 cm off,
// on the 10 frames it was tuned on, the median error is below issue 17's 0.3 deg / 3 cm. On drives
// it was not tuned on (`bench/calib_heldout_bench.cpp`, docs/results "Calibration") it is not.
// `--profile` (bench and CLI) prints the score along each axis and each frame's own peaks.
// On synthesised logs of the procedural scene (a tilting LMS 291 at 1 deg along its scan lines)
// `both` with 3 levels brings 1 deg / 5 cm starts to 0.17-0.53 deg / 1.9-7.6 cm: the sparse scan lines
// give depth edges across the lines only, so horizontal translation is weakly observed (from 4
// strokes instead of 6 one such start diverged to 1.75 deg / 44 cm: use more frames on logs).

#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

// One frame for calibration: an undistorted (rectified) camera image and the laser points seen at
// the same time, in the laser frame, in the scanner's beam order (neighbours along a scan line
// are consecutive, as in KITTI's Velodyne files and the tilting scanner's sweeps).
struct CalibFrame {
  std::string name;
  cv::Mat image;  // CV_8UC3 BGR or CV_8UC1
  Sweep sweep;
};

// The six axes of a laser->camera correction, about and along the camera's axes (x right, y down,
// z ahead): rotations rx ry rz, translations tx ty tz, in that order everywhere below.
using CalibAxes = std::array<bool, 6>;
const char* calibAxisName(int axis);  // "rx" ... "tz"
// The names of the axes set, in axis order, joined by separator ("" when none is set).
std::string calibAxisList(const CalibAxes& axes, const char* separator);
// {"tz"}, {"rx", "tz"} -> the axes named; throws std::invalid_argument naming an unknown one.
CalibAxes parseCalibAxes(const std::vector<std::string>& names);
// a relative to b about the camera axes: the rotation vector [deg] and the translation [m] of
// a * b^-1 (the 1-sigma of a result and its error against a truth are in these units).
Eigen::Matrix<double, 6, 1> poseDifference(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

enum class AlignmentMeasure { kMutualInformation, kEdges, kBoth };
AlignmentMeasure parseAlignmentMeasure(const std::string& name);  // mi | edges | both; throws otherwise
const char* alignmentMeasureName(AlignmentMeasure m);

struct TargetlessOptions {
  AlignmentMeasure measure = AlignmentMeasure::kEdges;
  int pyramidLevels = 1;           // level L-1 (coarsest, 1/2^(L-1) resolution) down to full resolution
  double rotationStepDeg = 2.0;    // start simplex size at the coarsest level; halved per finer level
  double translationStep = 0.10;   // [m], likewise
  int restartsPerLevel = 3;        // Nelder-Mead restarts from the best point while they improve
  int maxEvaluationsPerRun = 800;
  // The search stays within this distance of the start (beyond, the score is taken as worst): far
  // off, textured regions can outscore the true alignment.
  double maxRotationDeg = 6.0;
  double maxTranslation = 0.4;     // [m]
  double minDepth = 1.0;           // [m] points nearer the camera plane are not used
  double maxRange = 80.0;          // [m]
  // Points hidden in the camera's view behind nearer points (the laser sits elsewhere, so its
  // background leaks through foreground silhouettes) are dropped, judged under the start.
  bool removeOccluded = true;
  // Depth edges placed half way between the foreground sample and the background one behind it
  // (false: at the foreground sample, inside the object).
  bool edgeBetweenSamples = true;
  double edgeDecay = 0.8;          // max-decay spread of image edges per pixel of full resolution
  bool estimateUncertainty = true; // leave-one-frame-out jackknife at full resolution (>= 3 frames)
  // Axes kept at the start, never searched (`fusedet calibrate --hold`): one the frames cannot
  // constrain, or one measured with a tape.
  CalibAxes hold{};
};

// Summed agreement of frames under a transform (larger = better); exposed for tests and reports.
struct AlignmentScore {
  double mutualInformation = 0;  // [nats]
  double edgeAlignment = 0;      // edge strength at depth-edge points minus that at the others, [-1, 1]
  std::size_t points = 0;        // points that landed in an image
};

struct TargetlessResult {
  Eigen::Isometry3d laserToCamera = Eigen::Isometry3d::Identity();
  AlignmentScore before, after;   // at full resolution
  int evaluations = 0;            // cost evaluations, all levels and the jackknife
  // 1-sigma about the camera axes: rotation [deg] and translation [m], twice the leave-one-frame-out
  // jackknife spread in quadrature with a per-axis bias floor (rz 0.04 deg, tx 1.6 cm; factor and floor
  // measured on held-in drives, checked on held-out ones: docs/results "Calibration");
  // 0 for held axes; NaN when not estimated (fewer than 3 frames or estimateUncertainty false).
  Eigen::Vector3d rotationStdDeg = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d translationStd = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

// The result's 1-sigma per axis (rx ry rz [deg], tx ty tz [m]); NaN where not estimated.
Eigen::Matrix<double, 6, 1> sigmaPerAxis(const TargetlessResult& r);
// Axes the frames did not constrain: 1-sigma above the limit (or not estimated), held axes never.
CalibAxes uncertainAxes(const TargetlessResult& r, const CalibAxes& hold, double maxRotationDeg = 0.3,
                        double maxTranslation = 0.03);

// K: the pinhole of the undistorted images (pixel centres at integer coordinates). init maps laser
// points into the camera frame (x right, y down, z ahead). Throws std::invalid_argument when no frame
// has points in front of the camera or the images differ in size.
TargetlessResult calibrateTargetless(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K,
                                     const Eigen::Isometry3d& init, const TargetlessOptions& options = {});

// The scores of transforms at full resolution, with the points chosen under `reference`
// (the same points calibrateTargetless uses when reference is its init).
std::vector<AlignmentScore> scoreAlignments(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K,
                                            const Eigen::Isometry3d& reference,
                                            const std::vector<Eigen::Isometry3d>& candidates,
                                            const TargetlessOptions& options = {});

// Rotation angle [deg] and translation distance [m] between two transforms.
double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);
double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

}  // namespace fusedet::fusion
