// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers {

std::string_view toString(PixelFormat format) {
  switch (format) {
    case PixelFormat::kBgr24: return "BGR24";
    case PixelFormat::kGray8: return "GRAY8";
    case PixelFormat::kYuyv: return "YUYV";
    case PixelFormat::kMjpeg: return "MJPEG";
  }
  return "unknown";
}

}  // namespace fusedet::drivers
