// SPDX-License-Identifier: Apache-2.0
#pragma once
// The data of one run: KITTI drives found and imported once, their raw drives, object ids and items.

#include <filesystem>
#include <string>
#include <vector>

#include "options.h"

namespace fusedet::tools::experiments {
namespace fs = std::filesystem;

// Drive directories under a KITTI root: the three shared ones first (in the documented order),
// then any other directory holding image_2/, label_2/, velodyne/ and calib/.
std::vector<fs::path> kittiDrives(const fs::path& root);

// The data set to use: --data itself when it is one, else the KITTI drives under it imported
// once into the cache directory (a marker file records a finished import of the same drives and
// network: with --network the stacks also get its score layers).
fs::path resolveDataset(const ExperimentOptions& o);

// The raw drive of every manifest entry: from the SOURCE.md of the KITTI directory the entry's
// group was imported from (fusedet/fusion/datasets/kitti_drives.h), else the group itself.
std::vector<std::string> drivesOf(const ExperimentOptions& o, const std::vector<DatasetEntry>& manifest);

// The physical object of every label (fusedet/boost/learning_curve.h): "<drive>/track <id>" where the
// KITTI folder has its tracking label file (fusedet/fusion/datasets/kitti_tracks.h), else "" (counted once).
std::vector<std::vector<std::string>> objectIdsOf(const ExperimentOptions& o, const std::vector<DatasetEntry>& manifest,
                                                  const std::vector<Labels>& labels,
                                                  const std::vector<std::string>& driveOf);

// Items with their raw drive as group (the folds are drive-disjoint); the network's score layers
// too when `withNetwork`.
std::vector<DatasetItem> loadItems(const fs::path& dataset, const std::vector<DatasetEntry>& entries,
                                   const std::vector<std::string>& driveOf, bool withNetwork);

}  // namespace fusedet::tools::experiments
