// SPDX-License-Identifier: Apache-2.0
#pragma once
// KITTI frames as recorded scenes for SceneSource (Velodyne turn + camera image, each a 0.1 s
// sweep) and the Fuser for their calibration: the whole daemon on real data without devices
// (tests, the latency benchmark).

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fusedet/daemon/source.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::daemon {

struct KittiScenes {
  std::vector<PairedScene> scenes;
  std::shared_ptr<const fusion::Fuser> fuser;  // of the first frame's calibration
  std::vector<fusion::KittiFrame> frames;
};

// The image as a BGR24 camera frame (what a camera driver would deliver).
inline drivers::CameraFrame bgrFrame(const cv::Mat& image) {
  drivers::CameraFrame f;
  f.width = image.cols;
  f.height = image.rows;
  f.stride = image.cols * 3;
  f.format = drivers::PixelFormat::kBgr24;
  for (int y = 0; y < image.rows; ++y) f.bytes.insert(f.bytes.end(), image.ptr<std::uint8_t>(y), image.ptr<std::uint8_t>(y) + f.stride);
  return f;
}

// The given frame ids of the drive at `root` (all of one calibration). Throws like readKittiFrame.
inline KittiScenes loadKittiScenes(const std::filesystem::path& root, const std::vector<std::string>& ids) {
  KittiScenes out;
  for (const auto& id : ids) {
    fusion::KittiFrame f = fusion::readKittiFrame(root, id);
    PairedScene s;
    s.sweep = f.points;
    s.sweep.start = Stamp{0};
    s.sweep.end = Stamp{100'000'000};  // a Velodyne turn: 0.1 s
    s.frame = bgrFrame(f.image);
    if (!out.fuser) out.fuser = std::make_shared<const fusion::Fuser>(fusion::kittiFuser(f.calib, f.image.cols, f.image.rows));
    out.scenes.push_back(std::move(s));
    out.frames.push_back(std::move(f));
  }
  return out;
}

}  // namespace fusedet::daemon
