// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/device_list.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <cctype>

namespace fusedet::drivers::v4l2 {

std::vector<std::string> listVideoNodes(const std::filesystem::path& devDir) {
  std::vector<std::pair<unsigned long, std::string>> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(devDir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= 5 || name.compare(0, 5, "video") != 0) continue;
    if (!std::all_of(name.begin() + 5, name.end(), [](unsigned char c) { return std::isdigit(c); })) continue;
    found.emplace_back(std::stoul(name.substr(5)), entry.path().string());
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> nodes;
  for (auto& [n, path] : found) nodes.push_back(std::move(path));
  return nodes;
}

CameraDescription describeCamera(const std::string& device, std::unique_ptr<V4l2Io> io) {
  CameraDescription d;
  d.device = device;
  CameraConfig config;
  config.device = device;
  V4l2Camera camera(config, std::move(io));
  auto caps = camera.open();
  if (!caps) {
    d.error = caps.error().message();
    return d;
  }
  d.caps = *caps;
  auto formats = camera.enumerateFormats();
  if (!formats) {
    d.error = formats.error().message();
    return d;
  }
  d.formats = *formats;
  for (const FormatOffer& f : d.formats)
    for (const SizeRange& s : f.sizes) {
      if (!s.isDiscrete()) continue;
      auto iv = camera.enumerateIntervals(f.fourcc, s.minWidth, s.minHeight);
      if (!iv) {
        d.error = iv.error().message();
        return d;
      }
      d.intervals.push_back(SizeIntervals{f.fourcc, s.minWidth, s.minHeight, std::move(*iv)});
    }
  return d;
}

}  // namespace fusedet::drivers::v4l2
