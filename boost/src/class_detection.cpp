#include "fusedet/boost/class_detection.h"

#include "fusedet/boost/aspect_cascades.h"

#include <algorithm>
#include <iterator>

namespace fusedet::boosting {

std::optional<ClassDetection> classDetectionDefault(const std::string& className) {
  if (className != "car") return std::nullopt;
  // The daemon's scan (ScanParams{}: scale factor 1.1, step 2), more neighbours against the extra
  // windows it accepts, boxes widened to the laser's object (docs/results "Car at IoU 0.7").
  ClassDetection car;
  car.scaleFactor = 1.1;
  car.step = 2;
  car.minNeighbors = 16;
  car.laserExtent = true;
  return car;
}

std::vector<Detection> detectPerClass(const MultiDetector& detector, const LayerStack& stack, const ScanParams& scan,
                                      const GroupParams& group, const LaserExtentParams& extent,
                                      const std::vector<ClassGrouping>& perClass) {
  // Every model's cascades, aspect cascades included, merged per model (aspect_cascades.h).
  const std::vector<std::vector<std::vector<RawHit>>> hits = detector.scanModels(stack, scan);
  std::vector<Detection> out;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const std::string& name = detector.cascade(i).className;
    GroupParams g = group;
    LaserExtentParams e = extent;
    const auto own = std::find_if(perClass.begin(), perClass.end(),
                                  [&](const ClassGrouping& c) { return c.className == name; });
    if (own != perClass.end()) {
      g.minNeighbors = own->minNeighbors;
      e.enabled = own->laserExtent;
    }
    std::vector<Detection> d = groupModelHits(detector.cascade(i), hits[i], g, stack);
    refineToLaserExtent(d, stack, e);
    out.insert(out.end(), std::make_move_iterator(d.begin()), std::make_move_iterator(d.end()));
  }
  return out;
}

}  // namespace fusedet::boosting
