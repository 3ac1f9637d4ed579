// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/class_detection.h"

#include <algorithm>
#include <iterator>

namespace fusedet::boosting {

namespace {

struct OwnDetection {
  const char* className;
  ClassDetection settings;
};

// The classes with settings of their own. Car: the daemon's scan (ScanParams{}: scale factor 1.1,
// step 2), more neighbours against the extra windows it accepts, boxes widened to the laser's
// object (docs/results, "Options").
const std::vector<OwnDetection>& ownDetections() {
  static const std::vector<OwnDetection> table{{"car", ClassDetection{1.1, 2, 16, true}}};
  return table;
}

}  // namespace

std::optional<ClassDetection> classDetectionDefault(const std::string& className) {
  for (const OwnDetection& d : ownDetections())
    if (className == d.className) return d.settings;
  return std::nullopt;
}

std::vector<std::string> classesWithOwnDetection() {
  std::vector<std::string> out;
  for (const OwnDetection& d : ownDetections()) out.push_back(d.className);
  return out;
}

DetectionSetup classDetectionSetup(const std::string& className, const DetectionSetup& general,
                                   const SetForEveryClass& given) {
  DetectionSetup s = general;
  const std::optional<ClassDetection> own = classDetectionDefault(className);
  if (!own) return s;
  if (!given.scaleFactor) s.scan.scaleFactor = own->scaleFactor;
  if (!given.step) s.scan.step = own->step;
  if (!given.minNeighbors) s.group.minNeighbors = own->minNeighbors;
  if (!given.laserExtent) s.laserExtent.enabled = own->laserExtent;
  return s;
}

std::vector<ClassGrouping> classGroupings(const std::vector<std::string>& classNames, const GroupParams& group,
                                          const LaserExtentParams& extent, const SetForEveryClass& given) {
  DetectionSetup general;
  general.group = group;
  general.laserExtent = extent;
  std::vector<ClassGrouping> out;
  for (const std::string& name : classNames) {
    if (!classDetectionDefault(name)) continue;
    if (std::any_of(out.begin(), out.end(), [&](const ClassGrouping& c) { return c.className == name; })) continue;
    const DetectionSetup s = classDetectionSetup(name, general, given);
    out.push_back({name, s.group.minNeighbors, s.laserExtent.enabled});
  }
  return out;
}

std::vector<ClassGrouping> classGroupings(const MultiDetector& detector, const GroupParams& group,
                                          const LaserExtentParams& extent, const SetForEveryClass& given) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < detector.size(); ++i) names.push_back(detector.cascade(i).className);
  return classGroupings(names, group, extent, given);
}

GroupingOfClass groupingFor(const std::string& className, const std::vector<ClassGrouping>& perClass,
                            const GroupParams& group, const LaserExtentParams& extent) {
  GroupingOfClass out{group, extent, false};
  const auto own = std::find_if(perClass.begin(), perClass.end(),
                                [&](const ClassGrouping& c) { return c.className == className; });
  if (own == perClass.end()) return out;
  out.group.minNeighbors = own->minNeighbors;
  out.extent.enabled = own->laserExtent;
  out.own = true;
  return out;
}

std::vector<Detection> detectPerClass(const MultiDetector& detector, const LayerStack& stack, const ScanParams& scan,
                                      const GroupParams& group, const LaserExtentParams& extent,
                                      const std::vector<ClassGrouping>& perClass, PerClassWork* work) {
  const std::vector<std::vector<RawHit>> hits = detector.scan(stack, scan, work ? &work->scans : nullptr);
  if (work) {
    work->rawHits.assign(hits.size(), 0);
    work->detections.clear();
    for (std::size_t i = 0; i < hits.size(); ++i) work->rawHits[i] = hits[i].size();
  }
  std::vector<Detection> out;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const GroupingOfClass g = groupingFor(detector.cascade(i).className, perClass, group, extent);
    std::vector<Detection> d = groupHits(hits[i], g.group, detector.cascade(i).className, stack);
    refineToLaserExtent(d, stack, g.extent);
    if (work) work->detections.push_back(d.size());
    out.insert(out.end(), std::make_move_iterator(d.begin()), std::make_move_iterator(d.end()));
  }
  return out;
}

}  // namespace fusedet::boosting
