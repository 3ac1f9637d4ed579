// SPDX-License-Identifier: Apache-2.0
#include "fusedet/experiments/training_labels.h"

#include <set>
#include <stdexcept>
#include <string>

namespace fusedet::boosting {

std::vector<Labels> readTrainingLabels(const std::filesystem::path& dataset, const std::vector<DatasetItem>& items) {
  std::set<std::string> held;
  for (const DatasetEntry& e : readDatasetManifest(dataset)) held.insert(e.id);
  std::vector<Labels> labels;
  labels.reserve(items.size());
  for (const DatasetItem& item : items) {
    if (!held.count(item.id))
      throw std::runtime_error(dataset.string() + ": no item '" + item.id +
                               "': the training labels must come from a data set of the same items (e.g. an "
                               "autolabelled copy of the one tested on)");
    DatasetItem other = readDatasetItemLabels(dataset, item.id);
    if (other.stack.width() != item.stack.width() || other.stack.height() != item.stack.height())
      throw std::runtime_error(dataset.string() + ": item '" + item.id + "' is " + std::to_string(other.stack.width()) +
                               "x" + std::to_string(other.stack.height()) + " there but " +
                               std::to_string(item.stack.width()) + "x" + std::to_string(item.stack.height()) +
                               " in the data set tested on: not the same frame");
    labels.push_back(std::move(other.labels));
  }
  return labels;
}

}  // namespace fusedet::boosting
