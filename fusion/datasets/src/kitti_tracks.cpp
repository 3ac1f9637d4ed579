// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/kitti_tracks.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "fusedet/fusion/datasets/box_corners.h"

namespace fusedet::fusion {
namespace fs = std::filesystem;

int KittiTracks::trackOf(int frame, const Label& label) const {
  const auto it = frames.find(frame);
  if (it == frames.end()) return -1;
  const auto near = [](double a, double b) { return std::abs(a - b) <= 0.01; };
  for (const KittiTrackedBox& t : it->second)
    if (t.trackId >= 0 && t.type == label.sourceClass && near(t.box.x, label.box.x) && near(t.box.y, label.box.y) &&
        near(t.box.right(), label.box.right()) && near(t.box.bottom(), label.box.bottom()))
      return t.trackId;
  return -1;
}

std::vector<std::string> KittiTracks::objectIds(const std::string& drive, int frame, const Labels& labels) const {
  std::vector<std::string> out;
  out.reserve(labels.size());
  for (const Label& l : labels) {
    const int id = trackOf(frame, l);
    out.push_back(id < 0 ? std::string() : drive + "/track " + std::to_string(id));
  }
  return out;
}

KittiTracks parseKittiTracks(const std::string& text, const std::string& source) {
  KittiTracks tracks;
  std::istringstream in(text);
  std::string line;
  for (int lineNo = 1; std::getline(in, line); ++lineNo) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream f(line);
    int frame = 0, occluded = 0;
    double truncated = 0, alpha = 0, x1 = 0, y1 = 0, x2 = 0, y2 = 0;
    KittiTrackedBox t;
    if (!(f >> frame >> t.trackId >> t.type >> truncated >> occluded >> alpha >> x1 >> y1 >> x2 >> y2))
      throw std::runtime_error(source + ": line " + std::to_string(lineNo) +
                               ": expected frame, track id, class, truncated, occluded, alpha, bbox");
    const std::optional<Box> box = boxFromCorners(x1, y1, x2, y2);
    if (frame < 0 || t.trackId < -1 || !box)
      throw std::runtime_error(source + ": line " + std::to_string(lineNo) +
                               ": negative frame, track id below -1 or box of negative or non-finite size");
    t.box = *box;
    tracks.frames[frame].push_back(std::move(t));
  }
  return tracks;
}

KittiTracks readKittiTracks(const fs::path& root) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && name.rfind("tracking_label_02_", 0) == 0 && e.path().extension() == ".txt")
      files.push_back(e.path());
  }
  if (files.empty()) return {};
  if (files.size() > 1)
    throw std::runtime_error(root.string() + ": more than one tracking_label_02_*.txt (one drive per directory)");
  std::ifstream in(files.front());
  if (!in) throw std::runtime_error(files.front().string() + ": cannot open");
  std::stringstream s;
  s << in.rdbuf();
  return parseKittiTracks(s.str(), files.front().string());
}

}  // namespace fusedet::fusion
