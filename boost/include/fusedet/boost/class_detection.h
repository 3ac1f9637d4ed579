#pragma once
// Detection settings that differ by class. One pass of MultiDetector scans every class with one
// ScanParams; what follows the scan - the grouping's minimum of neighbours and the laser-extent box
// refinement - may differ per class, and so may the scan where each class is detected on its own
// (fusedet experiments).
//
// Car's settings were chosen on 3 drive-disjoint folds and confirmed on leave-one-drive-out at the
// devkit's IoU 0.7 with a paired interval above 0 (docs/results/README.md, "Car at IoU 0.7: method
// or data"). Person and bike keep the general settings (GroupParams{}, LaserExtentParams{}, the
// caller's scan): nothing measured beats them.

#include <optional>
#include <string>
#include <vector>

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

// What follows the shared scan for one class: `group` / `extent` with the class's minimum of
// neighbours and laser extent (only these two; the method and the rest stay).
struct ClassGrouping {
  std::string className;
  int minNeighbors = GroupParams{}.minNeighbors;
  bool laserExtent = LaserExtentParams{}.enabled;
};

// Scan + group for every model as detect(detector, stack, scan, group), then the laser-extent
// refinement; a model whose class is named in `perClass` is grouped with its minNeighbors and
// refined only if its laserExtent is set, every other model with `group` and `extent`.
std::vector<Detection> detectPerClass(const MultiDetector& detector, const LayerStack& stack, const ScanParams& scan,
                                      const GroupParams& group, const LaserExtentParams& extent,
                                      const std::vector<ClassGrouping>& perClass);

}  // namespace fusedet::boosting
