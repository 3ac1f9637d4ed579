#include "fusedet/boost/validation_part.h"

#include <algorithm>
#include <map>
#include <string>
#include <tuple>

namespace fusedet::boosting {

std::vector<std::size_t> validationItems(const std::vector<DatasetItem>& items, int part) {
  std::vector<std::size_t> held;
  if (part <= 0 || items.empty()) return held;
  const auto n = static_cast<std::size_t>(part);
  std::map<std::string, std::vector<std::size_t>> byGroup;
  for (std::size_t i = 0; i < items.size(); ++i) byGroup[items[i].group].push_back(i);

  if (byGroup.size() < 2) {
    // One drive: frame-disjoint, every n-th frame.
    for (std::size_t i = n - 1; i < items.size(); i += n) held.push_back(i);
    return held;
  }
  // Several drives: whole drives, smallest first, so that many drives (not one long one) decide.
  std::vector<const std::pair<const std::string, std::vector<std::size_t>>*> groups;
  for (const auto& g : byGroup) groups.push_back(&g);
  std::stable_sort(groups.begin(), groups.end(), [](const auto* a, const auto* b) {
    if (a->second.size() != b->second.size()) return a->second.size() < b->second.size();
    return a->first < b->first;
  });
  for (std::size_t g = 0; g + 1 < groups.size() && held.size() * n < items.size(); ++g)
    held.insert(held.end(), groups[g]->second.begin(), groups[g]->second.end());
  std::sort(held.begin(), held.end());
  return held;
}

std::optional<std::size_t> chooseStageCount(const std::vector<StageCountScore>& scores) {
  const StageCountScore* best = nullptr;
  const auto key = [](const StageCountScore& s) {
    return std::make_tuple(s.f.value_or(-1.0), s.ap.value_or(-1.0), s.stages);
  };
  for (const StageCountScore& s : scores)
    if (!best || key(s) > key(*best)) best = &s;
  if (!best || !(best->f.value_or(0) > 0)) return std::nullopt;
  return best->stages;
}

}  // namespace fusedet::boosting
