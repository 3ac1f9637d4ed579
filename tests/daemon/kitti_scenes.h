#pragma once
// Test and benchmark support: real KITTI frames (../shared/data) as the daemon's recorded scenes
// (Velodyne sweep + camera image) and the Fuser for their calibration.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fusedet/daemon/source.h"
#include "fusedet/fusion/kitti.h"

namespace fusedet::kitti_scenes {

struct KittiScenes {
  std::vector<daemon::PairedScene> scenes;
  std::shared_ptr<const fusion::Fuser> fuser;  // of the first frame's calibration
  std::vector<fusion::KittiFrame> frames;
};

inline drivers::CameraFrame bgrFrame(const cv::Mat& image) {
  drivers::CameraFrame f;
  f.width = image.cols;
  f.height = image.rows;
  f.stride = image.cols * 3;
  f.format = drivers::PixelFormat::kBgr24;
  for (int y = 0; y < image.rows; ++y) f.bytes.insert(f.bytes.end(), image.ptr<std::uint8_t>(y), image.ptr<std::uint8_t>(y) + f.stride);
  return f;
}

// The given frame ids of the drive at `root` (all of one calibration).
inline KittiScenes loadKittiScenes(const std::filesystem::path& root, const std::vector<std::string>& ids) {
  KittiScenes out;
  for (const auto& id : ids) {
    fusion::KittiFrame f = fusion::readKittiFrame(root, id);
    daemon::PairedScene s;
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

inline std::filesystem::path kittiRoot() { return std::filesystem::path(FUSEDET_DATA_DIR) / "kitti"; }

}  // namespace fusedet::kitti_scenes
