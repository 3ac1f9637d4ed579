// SPDX-License-Identifier: Apache-2.0
#pragma once
// Labels to train on from another data set of the same items (fusedet experiments --train-labels):
// e.g. an autolabelled copy (fusedet autolabel: teacher labels only, or teacher + human), while every
// held-out item is still scored against the labels of the data set it was read from. The fold
// models trained on them are keyed by their labelsKey() (cross_validation.h ChainSpec::trainingLabels).

#include <filesystem>
#include <vector>

#include "fusedet/core/dataset.h"
#include "fusedet/core/label.h"

namespace fusedet::boosting {

// The labels `dataset` holds for each of `items` (by id, in the items' order). Throws
// std::runtime_error naming the data set and the item when it lacks one of the items or holds it
// with another image size (the boxes would be in another frame), and what readDatasetManifest()
// and readDatasetItemLabels() throw for a missing or malformed data set.
std::vector<Labels> readTrainingLabels(const std::filesystem::path& dataset, const std::vector<DatasetItem>& items);

}  // namespace fusedet::boosting
