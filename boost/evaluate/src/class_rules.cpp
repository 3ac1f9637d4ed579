// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/class_rules.h"

#include <stdexcept>

namespace fusedet::boosting {

VanPolicy parseVanPolicy(const std::string& text) {
  if (text == "ignore") return VanPolicy::kIgnore;
  if (text == "negative") return VanPolicy::kNegative;
  if (text == "positive") return VanPolicy::kPositive;
  throw std::invalid_argument("van policy '" + text + "' is not one of ignore, negative, positive");
}

std::string toString(VanPolicy policy) {
  switch (policy) {
    case VanPolicy::kIgnore: return "ignore";
    case VanPolicy::kNegative: return "negative";
    case VanPolicy::kPositive: return "positive";
  }
  return "?";
}

double kittiMinOverlap(const std::string& className) { return className == "car" ? 0.7 : 0.5; }

MatchConfig matchConfigFor(const std::string& className, VanPolicy van, double minIou) {
  MatchConfig c;
  c.className = className;
  c.minIou = minIou > 0 ? minIou : kittiMinOverlap(className);
  if (className == "car" && van == VanPolicy::kIgnore) c.neighbourClasses = {"van", "Van"};
  if (className == "car" && van == VanPolicy::kPositive) c.aliasClasses = {"van"};
  if (className == "person") c.neighbourClasses = {"Person_sitting"};
  return c;
}

Labels trainingLabels(const Labels& labels, const MatchConfig& config) {
  Labels out;
  for (const Label& l : labels) {
    switch (labelRole(l, config)) {
      case LabelRole::kPositive: {
        Label p = l;
        p.className = config.className;  // aliases (van as car) train as the class
        out.push_back(std::move(p));
        break;
      }
      case LabelRole::kIgnoredLabel:
      case LabelRole::kIgnoreRegion: {
        Label r = l;
        r.ignore = true;
        out.push_back(std::move(r));
        break;
      }
      case LabelRole::kBackground:
        break;
    }
  }
  return out;
}

InstanceCount countInstances(const std::vector<Labels>& frames, const MatchConfig& config) {
  InstanceCount n;
  for (const Labels& labels : frames) {
    bool any = false;
    for (const Label& l : labels) {
      const auto role = labelRole(l, config);
      if (role == LabelRole::kPositive) {
        ++n.positives;
        any = true;
      } else if (role == LabelRole::kIgnoredLabel) {
        ++n.ignoredLabels;
      }
    }
    if (any) ++n.frames;
  }
  return n;
}

}  // namespace fusedet::boosting
