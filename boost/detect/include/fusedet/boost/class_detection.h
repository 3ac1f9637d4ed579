// SPDX-License-Identifier: Apache-2.0
#pragma once
// Detection settings that differ by class. One pass of MultiDetector scans every class with one
// ScanParams; what follows the scan - the grouping's minimum of neighbours and the laser-extent box
// refinement - may differ per class, and so may the scan where each class is detected on its own
// (fusedet experiments).
//
// Car's settings were chosen on 3 drive-disjoint folds and confirmed on leave-one-drive-out at the
// devkit's IoU 0.7 with a paired interval above 0 (docs/results/README.md, "Options": F +0.071
// [+0.007, +0.138]). Person and bike keep the general settings (GroupParams{}, LaserExtentParams{},
// the caller's scan): nothing measured beats them.

#include <optional>
#include <string>
#include <vector>

#include "fusedet/boost/detection_setup.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/laser_extent.h"
#include "fusedet/boost/multi_detector.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

struct ClassDetection {
  double scaleFactor = ScanParams{}.scaleFactor;  // where the class is scanned on its own
  double step = ScanParams{}.step;
  int minNeighbors = GroupParams{}.minNeighbors;
  bool laserExtent = LaserExtentParams{}.enabled;
};

// The class's own settings, or nullopt when the general ones apply (every class but car).
std::optional<ClassDetection> classDetectionDefault(const std::string& className);

// Every class that has settings of its own (car), in a fixed order.
std::vector<std::string> classesWithOwnDetection();

// General settings a command line or config set explicitly "for every class": each one given
// replaces that setting of every class's own (a class keeps its own for the others).
struct SetForEveryClass {
  bool scaleFactor = false, step = false, minNeighbors = false, laserExtent = false;
};

// The settings `className` is detected with when it is scanned on its own (fusedet experiments):
// `general`, with the class's own setting (classDetectionDefault) in place of each one not `given`.
// A class without settings of its own gets `general` unchanged.
DetectionSetup classDetectionSetup(const std::string& className, const DetectionSetup& general,
                                   const SetForEveryClass& given = {});

// What follows the shared scan for one class: `group` / `extent` with the class's minimum of
// neighbours and laser extent (only these two; the method and the rest stay).
struct ClassGrouping {
  std::string className;
  int minNeighbors = GroupParams{}.minNeighbors;
  bool laserExtent = LaserExtentParams{}.enabled;
};

// THE rule "which grouping does a class get" where every class shares one scan (fusedetd's
// built-in detection.classes, fusedet demo and detect): one entry per class of `classNames` that
// has settings of its own, in their order, each once; its minNeighbors / laserExtent are those
// classDetectionSetup() gives (the general value where `given`, else the class's own). Classes
// without settings of their own get no entry: detectPerClass() groups them with the general ones.
std::vector<ClassGrouping> classGroupings(const std::vector<std::string>& classNames, const GroupParams& group = {},
                                          const LaserExtentParams& extent = {}, const SetForEveryClass& given = {});
// The same for the classes of the detector's models.
std::vector<ClassGrouping> classGroupings(const MultiDetector& detector, const GroupParams& group = {},
                                          const LaserExtentParams& extent = {}, const SetForEveryClass& given = {});

// The grouping one class gets after the shared scan: `group` / `extent` with the minNeighbors /
// laser extent of the class's entry in `perClass` if it has one (`own`), else unchanged. The one
// lookup detectPerClass() groups with and commands print.
struct GroupingOfClass {
  GroupParams group;
  LaserExtentParams extent;
  bool own = false;
};
GroupingOfClass groupingFor(const std::string& className, const std::vector<ClassGrouping>& perClass,
                            const GroupParams& group, const LaserExtentParams& extent);

// Work done by detectPerClass(), per model (index = model order).
struct PerClassWork {
  std::vector<ScanStats> scans;
  std::vector<std::size_t> rawHits;     // per model
  std::vector<std::size_t> detections;  // the output holds model 0's first, then model 1's, ...
};

// Scan + group for every model as detect(detector, stack, scan, group), then the laser-extent
// refinement; a model whose class is named in `perClass` is grouped with its minNeighbors and
// refined only if its laserExtent is set, every other model with `group` and `extent`.
std::vector<Detection> detectPerClass(const MultiDetector& detector, const LayerStack& stack, const ScanParams& scan,
                                      const GroupParams& group, const LaserExtentParams& extent,
                                      const std::vector<ClassGrouping>& perClass, PerClassWork* work = nullptr);

}  // namespace fusedet::boosting
