// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/calib_kitti.h"

#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace fusedet::fusion {
namespace fs = std::filesystem;

namespace {

bool sameRig(const KittiCalib& a, const KittiCalib& b) {
  return a.P2 == b.P2 && a.R0rect == b.R0rect && a.TrVeloToCam == b.TrVeloToCam;
}

struct Candidate {
  fs::path root;
  std::string id;
  std::size_t rig;
};

}  // namespace

KittiCalibrationInput loadKittiCalibrationInput(const std::vector<fs::path>& roots, std::size_t maxFrames) {
  if (maxFrames == 0) throw std::invalid_argument("calibration needs at least one frame");
  std::vector<KittiCalib> rigs;
  std::vector<std::size_t> rigCount;
  std::vector<Candidate> candidates;
  for (const fs::path& root : roots) {
    for (const std::string& id : listKittiFrames(root)) {
      const KittiCalib c = readKittiCalib(root / "calib" / (id + ".txt"));
      std::size_t rig = 0;
      while (rig < rigs.size() && !sameRig(rigs[rig], c)) ++rig;
      if (rig == rigs.size()) {
        rigs.push_back(c);
        rigCount.push_back(0);
      }
      ++rigCount[rig];
      candidates.push_back({root, id, rig});
    }
  }
  if (candidates.empty()) throw std::invalid_argument("no KITTI frames (image_2/*.png) in the directories given");
  std::size_t chosen = 0;
  for (std::size_t r = 1; r < rigs.size(); ++r)
    if (rigCount[r] > rigCount[chosen]) chosen = r;
  std::vector<const Candidate*> rigFrames;
  for (const Candidate& c : candidates)
    if (c.rig == chosen) rigFrames.push_back(&c);

  KittiCalibrationInput in;
  in.calib = rigs[chosen];
  in.rigFrames = rigFrames.size();
  in.otherRigFrames = candidates.size() - rigFrames.size();
  const std::size_t take = std::min(maxFrames, rigFrames.size());
  for (std::size_t k = 0; k < take; ++k) {
    // Evenly spread, first and last included: different scenes constrain different directions.
    const std::size_t i = take == 1 ? 0 : k * (rigFrames.size() - 1) / (take - 1);
    const Candidate& c = *rigFrames[i];
    CalibFrame f;
    const fs::path dir = c.root.has_filename() ? c.root : c.root.parent_path();  // "kitti/" too
    f.name = dir.filename().string() + "/" + c.id;
    const fs::path image = c.root / "image_2" / (c.id + ".png");
    f.image = cv::imread(image.string(), cv::IMREAD_COLOR);
    if (f.image.empty()) throw std::runtime_error(image.string() + ": cannot read image");
    f.sweep = readKittiVelodyne(c.root / "velodyne" / (c.id + ".bin"));
    in.frames.push_back(std::move(f));
  }
  const PinholeProjection p = kittiProjection(in.calib, in.frames.front().image.cols, in.frames.front().image.rows);
  in.K = p.K;
  in.laserToCamera = p.sweepToCamera;
  return in;
}

}  // namespace fusedet::fusion
