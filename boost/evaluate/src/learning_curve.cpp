// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/learning_curve.h"

#include <set>

namespace fusedet::boosting {

std::vector<std::size_t> positivesPerItem(const std::vector<Labels>& labels, const MatchConfig& match) {
  std::vector<std::size_t> out;
  out.reserve(labels.size());
  for (const Labels& ls : labels) {
    std::size_t n = 0;
    for (const Label& l : ls) n += labelRole(l, match) == LabelRole::kPositive ? 1 : 0;
    out.push_back(n);
  }
  return out;
}

TrainingSetCount countTrainingSet(const Fold& fold, const std::vector<Labels>& labels,
                                  const std::vector<std::string>& groupOfItem,
                                  const std::vector<std::vector<std::string>>& objectIdOf, const MatchConfig& match) {
  TrainingSetCount c;
  std::set<std::string> groups, objects;
  std::size_t unnamed = 0;
  for (std::size_t i : fold.train) {
    ++c.items;
    groups.insert(groupOfItem.at(i));
    const Labels& ls = labels.at(i);
    for (std::size_t j = 0; j < ls.size(); ++j) {
      if (labelRole(ls[j], match) != LabelRole::kPositive) continue;
      ++c.positives;
      const std::string* id = i < objectIdOf.size() && j < objectIdOf[i].size() ? &objectIdOf[i][j] : nullptr;
      if (id && !id->empty())
        objects.insert(*id);
      else
        ++unnamed;
    }
  }
  c.groups = groups.size();
  c.objects = objects.size() + unnamed;
  return c;
}

}  // namespace fusedet::boosting
