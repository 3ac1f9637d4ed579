#include "fusedet/boost/class_rules.h"

#include <algorithm>
#include <cmath>
#include <sstream>
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

TrainingPositives parseTrainingPositives(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("training positives '" + text + "': " + why +
                                 " (expected moderate|hard[,vans][,min-height=N])");
  };
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');) parts.push_back(part);
  if (parts.empty() || text.back() == ',') throw bad("empty part");
  TrainingPositives rule;
  if (parts[0] == "moderate") rule.level = TrainingPositives::Level::kModerate;
  else if (parts[0] == "hard") rule.level = TrainingPositives::Level::kHard;
  else throw bad("level '" + parts[0] + "' is not moderate or hard");
  bool heightGiven = false;
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const std::string& p = parts[i];
    if (p == "vans") {
      if (rule.vans) throw bad("vans given twice");
      rule.vans = true;
    } else if (p.rfind("min-height=", 0) == 0) {
      if (heightGiven) throw bad("min-height given twice");
      const std::string number = p.substr(11);
      std::size_t used = 0;
      double h = 0;
      try {
        h = std::stod(number, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (number.empty() || used != number.size() || !std::isfinite(h) || h <= 0)
        throw bad("min-height '" + number + "' is not a number of pixels > 0");
      rule.minHeight = h;
      heightGiven = true;
    } else {
      throw bad("unknown part '" + p + "'");
    }
  }
  return rule;
}

std::string toString(const TrainingPositives& rule) {
  std::string s = rule.level == TrainingPositives::Level::kHard ? "hard" : "moderate";
  if (rule.vans) s += ",vans";
  if (rule.minHeight > 0) {
    std::ostringstream h;
    h << rule.minHeight;
    s += ",min-height=" + h.str();
  }
  return s;
}

MatchConfig trainingMatchConfig(const MatchConfig& evaluation, const TrainingPositives& rule, bool truncationLevels) {
  MatchConfig c = evaluation;
  if (rule.level == TrainingPositives::Level::kHard) {
    c.maxOcclusion = 2;
    c.maxTruncation = truncationLevels ? 1 : 0.5;
  }
  if (rule.minHeight > 0) c.minHeight = rule.minHeight;
  if (rule.vans) {
    if (evaluation.className != "car")
      throw std::invalid_argument("training positives: vans train only as car, not as '" + evaluation.className + "'");
    const auto isVan = [](const std::string& n) { return n == "van" || n == "Van"; };
    c.neighbourClasses.erase(std::remove_if(c.neighbourClasses.begin(), c.neighbourClasses.end(), isVan),
                             c.neighbourClasses.end());
    if (std::find(c.aliasClasses.begin(), c.aliasClasses.end(), "van") == c.aliasClasses.end())
      c.aliasClasses.push_back("van");
  }
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
