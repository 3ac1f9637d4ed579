// SPDX-License-Identifier: Apache-2.0
#pragma once
// Laser-extent box refinement: a detection's left and right edges moved outwards to where the
// object's cluster in the `distance` layer ends. The cascade scans one window aspect (car 36x24 =
// 1.5) and its groups average windows, so a car box is often too narrow at the KITTI devkit's
// IoU 0.7; the laser sees the object's extent. Off in the general settings (car uses it with its
// own scan and neighbours: class_detection.h); alone, car F at IoU 0.7 rises from 0.43
// to 0.49 on 3 drive-disjoint folds but only from 0.51 to 0.53 leave-one-drive-out (+4 hits of
// 186; paired interval of the difference +0.02 [-0.005, 0.05]: a tie across drives; `fusedet
// compare`, docs/results/README.md "Options").
//
// Rule, in the distance layer's cells (the box read through laser_cells.h, which owns the band,
// the core and the box's distance):
//  - band: the box's rows from 35 % to 85 % of its height (a car's body below the windows, which
//    the laser passes through); core: the band's middle half of the columns;
//  - reference distance d0 = LaserCells::coreDepth, the median of the core's valid cells (mask
//    non-zero and distance > 0); fewer than minCells valid core cells -> the box is returned
//    unchanged (no laser on it);
//  - a column is on the object when at least minShare of its valid band cells lie within
//    tolerance of the reference, which then becomes the median of those cells (a car's side seen
//    at a slant continues; the jump to the background ends); a column without valid cells continues;
//  - from the box's centre column (which must be on the object) walk outwards, at most maxMove x
//    the box's width beyond each edge; the last object column, widened by margin x the box's width
//    (the laser's silhouette lies inside the labelled one), is the new edge if it lies outside the
//    box. A walk that reaches its limit finds no end (a neighbour, a wall): that edge stays.
// Top and bottom stay: the laser passes through windows and meets the ground under the car.

#include <vector>

#include "fusedet/core/box.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

struct LaserExtentParams {
  bool enabled = false;
  double tolerance = 1.0;  // [m] from the previous object column's median distance
  double minShare = 0.5;   // share of a column's valid band cells on the object
  double maxMove = 0.3;    // largest edge move, fraction of the box's width
  double margin = 0.05;    // the laser's edges widened by this fraction of the box's width
  int minCells = 6;        // valid core cells needed
};

// The refined box (reference pixels of `stack`); `box` itself when params.enabled is false, the
// stack has no distance layer, or the box too few laser cells.
Box laserExtentBox(const Box& box, const LayerStack& stack, const LaserExtentParams& params);

// Every detection's box (and unitBox) refined in place.
void refineToLaserExtent(std::vector<Detection>& detections, const LayerStack& stack, const LaserExtentParams& params);

}  // namespace fusedet::boosting
