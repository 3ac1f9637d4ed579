#include "fusedet/daemon/stack_detector.h"

#include <set>
#include <stdexcept>

#include "fusedet/boost/model_io.h"

namespace fusedet::daemon {

boosting::ScanParams scanParamsFrom(const Config::Detection& d) {
  boosting::ScanParams p;
  p.scaleFactor = d.scaleFactor;
  p.minWidth = d.minSize[0];
  p.minHeight = d.minSize[1];
  p.maxWidth = d.maxSize[0];
  p.maxHeight = d.maxSize[1];
  p.step = d.step;
  p.threads = d.threads;
  return p;
}

boosting::GroupParams groupParamsFrom(const Config::Detection& d) {
  boosting::GroupParams g;
  g.method = d.grouping == "nms" ? boosting::GroupParams::Method::kNms : boosting::GroupParams::Method::kOpenCv;
  g.minNeighbors = d.minNeighbors;
  g.iouThreshold = d.nmsIou;
  return g;
}

CascadeSet::CascadeSet(const Config::Detection& settings, const std::filesystem::path& base)
    : scan_(scanParamsFrom(settings)), group_(groupParamsFrom(settings)) {
  if (settings.models.empty()) throw std::runtime_error("detection.models: no model files configured");
  std::set<std::string> seen;
  for (const auto& m : settings.models) {
    std::filesystem::path file = m;
    if (file.is_relative() && !base.empty()) file = base / file;
    try {
      boosting::Detector detector(boosting::loadModel(file));
      const std::string& name = detector.cascade().className;
      if (!seen.insert(name).second)
        throw std::runtime_error(file.string() + ": a second model of class '" + name + "'");
      detectors_.push_back(std::move(detector));
      files_.push_back(file);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(file.string() + ": " + e.what());
    }
  }
}

std::vector<Detection> CascadeSet::detect(const LayerStack& stack) const {
  std::vector<Detection> all;
  for (const auto& d : detectors_) {
    auto found = boosting::detect(d, stack, scan_, group_);
    all.insert(all.end(), std::make_move_iterator(found.begin()), std::make_move_iterator(found.end()));
  }
  return all;
}

std::vector<std::string> CascadeSet::classes() const {
  std::vector<std::string> names;
  for (const auto& d : detectors_) names.push_back(d.cascade().className);
  return names;
}

}  // namespace fusedet::daemon
