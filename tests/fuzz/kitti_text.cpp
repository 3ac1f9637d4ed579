// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: KITTI text files - a frame's calib (P2, R0_rect, Tr_velo_to_cam), its
// label_2 object labels and a drive's tracking labels - as the importers read them. The input is
// offered to each reader (a calib file is not a label file, so most inputs are refused by some);
// std::runtime_error naming the file is the only refusal allowed. Accepted boxes are finite with
// a size >= 0, and a calib that passes kittiProjection projects with finite numbers.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "fusedet/fusion/datasets/kitti.h"
#include "fusedet/fusion/datasets/kitti_tracks.h"
#include "memory_file.h"

namespace {

bool sane(const fusedet::Box& b) {
  return std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.w) && std::isfinite(b.h) && b.w >= 0 && b.h >= 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet::fusion;
  const fusedet::fuzz::MemoryFile file(data, size);
  if (!file.ok()) return 0;
  const auto namesFile = [&](const std::runtime_error& e) {
    if (std::string(e.what()).find(file.path()) == std::string::npos) std::abort();
  };
  try {
    const KittiCalib calib = readKittiCalib(file.path());
    try {
      const PinholeProjection p = kittiProjection(calib, 1242, 375);
      if (!p.K.allFinite() || !p.sweepToCamera.matrix().allFinite()) std::abort();
    } catch (const std::runtime_error&) {  // not of the form K [I | t]: a refusal, not a finding
    }
  } catch (const std::runtime_error& e) {
    namesFile(e);
  }
  try {
    for (const fusedet::Label& l : readKittiLabels(file.path()))
      if (!sane(l.box)) std::abort();
  } catch (const std::runtime_error& e) {
    namesFile(e);
  }
  try {
    const KittiTracks tracks = parseKittiTracks(std::string(reinterpret_cast<const char*>(data), size), file.path());
    for (const auto& [frame, boxes] : tracks.frames) {
      if (frame < 0) std::abort();
      fusedet::Labels labels;
      for (const KittiTrackedBox& b : boxes) {
        if (!sane(b.box) || b.trackId < -1) std::abort();
        labels.push_back(fusedet::Label{"", b.type, b.box, 0, 0, false});
      }
      const auto ids = tracks.objectIds("drive", frame, labels);
      if (ids.size() != labels.size()) std::abort();
    }
  } catch (const std::runtime_error& e) {
    namesFile(e);
  }
  return 0;
}
