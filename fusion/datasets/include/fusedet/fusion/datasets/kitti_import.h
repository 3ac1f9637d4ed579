// SPDX-License-Identifier: Apache-2.0
#pragma once
// KITTI import: each frame of a KITTI-layout directory goes through the same projection code as
// live data (Fuser) and is written as one item of a data set (core/dataset.h). One directory =
// one group (its directory name), for splitting by drive.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "fusedet/core/dataset.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::fusion {

struct KittiImportOptions {
  ProjectionConfig projection;
  KittiClassMap classes;  // Van -> "van" by default: a hard negative for car, not an ignore region
  std::shared_ptr<const NeuralLayers> neural;  // optional: the network's score layers too (fuser.h)
};

// Fuses one read frame into a data set item with id "<group>/<frame id>".
DatasetItem fuseKittiFrame(const KittiFrame& frame, const std::string& group, const ProjectionConfig& config,
                           FuseTimings* timings = nullptr, std::shared_ptr<const NeuralLayers> neural = {});

struct KittiImportStats {
  std::size_t frames = 0;
  std::size_t labels = 0;         // all labels written, ignore regions included
  std::size_t ignoreRegions = 0;
  double fuseMs = 0;              // summed Fuser time (reading and writing files excluded)
  double neuralMs = 0;            // of which the network's score layers
};

// Imports every frame of `root` (listKittiFrames order) into `datasetDir` under `group`.
// `progress` (optional) is called after each frame with its item. Throws on the first bad frame,
// naming its file.
KittiImportStats importKitti(const std::filesystem::path& root, const std::string& group,
                             const std::filesystem::path& datasetDir, const KittiImportOptions& options,
                             const std::function<void(const DatasetItem&)>& progress = {});

}  // namespace fusedet::fusion
