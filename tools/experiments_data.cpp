#include "experiments_data.h"

#include <cmath>
#include <stdexcept>

namespace fusedet::tools::experiments {

Split splitByFrame(const std::vector<DatasetEntry>& entries, double trainFraction) {
  if (!(trainFraction >= 0 && trainFraction <= 1))
    throw std::invalid_argument("train fraction must be in [0, 1]");
  // Groups in order of first appearance; items keep manifest order inside a group.
  std::vector<std::string> groups;
  std::map<std::string, std::vector<DatasetEntry>> byGroup;
  for (const DatasetEntry& e : entries) {
    auto [it, fresh] = byGroup.try_emplace(e.group);
    if (fresh) groups.push_back(e.group);
    it->second.push_back(e);
  }
  Split split;
  for (const std::string& g : groups) {
    const auto& items = byGroup[g];
    const auto nTrain = static_cast<std::size_t>(std::lround(static_cast<double>(items.size()) * trainFraction));
    for (std::size_t i = 0; i < items.size(); ++i) (i < nTrain ? split.train : split.test).push_back(items[i]);
  }
  return split;
}

VanPolicy parseVanPolicy(const std::string& text) {
  if (text == "negative") return VanPolicy::kNegative;
  if (text == "ignore") return VanPolicy::kIgnore;
  if (text == "positive") return VanPolicy::kPositive;
  throw std::invalid_argument("van policy '" + text + "' is not one of negative, ignore, positive");
}

std::string toString(VanPolicy policy) {
  switch (policy) {
    case VanPolicy::kNegative: return "negative";
    case VanPolicy::kIgnore: return "ignore";
    case VanPolicy::kPositive: return "positive";
  }
  return "?";
}

boosting::MatchConfig matchConfigFor(const std::string& className, VanPolicy van) {
  boosting::MatchConfig c;
  c.className = className;
  if (className == "car" && van == VanPolicy::kIgnore) c.ignoreClasses = {"van"};
  if (className == "car" && van == VanPolicy::kPositive) c.aliasClasses = {"van"};
  return c;
}

Labels trainingLabels(const Labels& labels, const boosting::MatchConfig& config) {
  Labels out;
  for (const Label& l : labels) {
    switch (boosting::labelRole(l, config)) {
      case boosting::LabelRole::kPositive: {
        Label p = l;
        p.className = config.className;  // aliases (van as car) train as the class
        out.push_back(std::move(p));
        break;
      }
      case boosting::LabelRole::kIgnoredLabel:
      case boosting::LabelRole::kIgnoreRegion: {
        Label r = l;
        r.ignore = true;
        out.push_back(std::move(r));
        break;
      }
      case boosting::LabelRole::kBackground:
        break;
    }
  }
  return out;
}

InstanceCount countInstances(const std::vector<Labels>& frames, const boosting::MatchConfig& config) {
  InstanceCount n;
  for (const Labels& labels : frames) {
    bool any = false;
    for (const Label& l : labels) {
      const auto role = boosting::labelRole(l, config);
      if (role == boosting::LabelRole::kPositive) {
        ++n.positives;
        any = true;
      } else if (role == boosting::LabelRole::kIgnoredLabel) {
        ++n.ignoredLabels;
      }
    }
    if (any) ++n.frames;
  }
  return n;
}

}  // namespace fusedet::tools::experiments
