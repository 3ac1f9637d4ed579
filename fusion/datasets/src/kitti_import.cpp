// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/kitti_import.h"

#include <charconv>

namespace fusedet::fusion {

DatasetItem fuseKittiFrame(const KittiFrame& frame, const std::string& group, const ProjectionConfig& config,
                           FuseTimings* timings, std::shared_ptr<const NeuralLayers> neural) {
  const Fuser fuser = kittiFuser(frame.calib, frame.image.cols, frame.image.rows, config, std::move(neural));
  DatasetItem item;
  item.group = group;
  item.id = group + "/" + frame.id;
  item.stack = fuser.fuse(frame.image, frame.points, timings);
  item.stack.source = group + "/" + frame.id;
  std::uint64_t index = 0;
  const auto [ptr, ec] = std::from_chars(frame.id.data(), frame.id.data() + frame.id.size(), index);
  if (ec == std::errc() && ptr == frame.id.data() + frame.id.size()) item.stack.id = index;
  item.labels = frame.labels;
  return item;
}

KittiImportStats importKitti(const std::filesystem::path& root, const std::string& group,
                             const std::filesystem::path& datasetDir, const KittiImportOptions& options,
                             const std::function<void(const DatasetItem&)>& progress) {
  KittiImportStats stats;
  for (const std::string& id : listKittiFrames(root)) {
    const KittiFrame frame = readKittiFrame(root, id, options.classes);
    FuseTimings t;
    const DatasetItem item = fuseKittiFrame(frame, group, options.projection, &t, options.neural);
    writeDatasetItem(datasetDir, item);
    ++stats.frames;
    stats.fuseMs += t.totalMs;
    stats.neuralMs += t.neuralMs;
    stats.labels += item.labels.size();
    for (const Label& l : item.labels) stats.ignoreRegions += l.ignore ? 1 : 0;
    if (progress) progress(item);
  }
  return stats;
}

}  // namespace fusedet::fusion
