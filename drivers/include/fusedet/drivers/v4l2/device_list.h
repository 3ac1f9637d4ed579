// SPDX-License-Identifier: Apache-2.0
#pragma once
// Finding and describing V4L2 nodes for `fusedet camera list`: which /dev/videoN exist, what
// each can do and, for capture devices, every format, size and frame interval offered.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/drivers/v4l2/camera.h"

namespace fusedet::drivers::v4l2 {

// <devDir>/videoN nodes, sorted by N.
std::vector<std::string> listVideoNodes(const std::filesystem::path& devDir = "/dev");

struct SizeIntervals {
  std::uint32_t fourcc = 0, width = 0, height = 0;
  std::vector<IntervalRange> intervals;
};

struct CameraDescription {
  std::string device;
  std::optional<Capabilities> caps;  // empty when the node could not be opened or is not V4L2
  std::string error;                 // why the node cannot be captured from (empty when it can)
  std::vector<FormatOffer> formats;
  std::vector<SizeIntervals> intervals;  // for each discrete size
  bool usable() const { return error.empty(); }
};

CameraDescription describeCamera(const std::string& device, std::unique_ptr<V4l2Io> io = makeKernelIo());

}  // namespace fusedet::drivers::v4l2
