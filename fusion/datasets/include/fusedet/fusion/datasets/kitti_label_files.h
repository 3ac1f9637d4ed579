// SPDX-License-Identifier: Apache-2.0
#pragma once
// A folder of KITTI label_2 files for labels in and out of a data set: DIR/<item id>.txt, one object
// per line "type truncated occluded alpha x1 y1 x2 y2 h w l x y z rotation_y" (Geiger et al.,
// IJRR 2013). A 2D label has no 3D box: written as KITTI writes DontCare (-1 -1 -1 -1000 -1000
// -1000 -10) with alpha -10. Ignore regions are written as their own KITTI class when it is one of
// KITTI's, else DontCare.

#include <filesystem>
#include <vector>

#include "fusedet/fusion/datasets/label_exchange.h"

namespace fusedet::fusion {

// The KITTI type of a label: person -> Pedestrian, car -> Car, bike -> Cyclist, van -> Van.
std::string kittiClassName(const Label& label);

// Writes one file per image (folders of the item id are made); returns the files written.
std::size_t writeKittiLabelFiles(const std::filesystem::path& dir, const std::vector<ExchangeImage>& images);

// Every DIR/**/*.txt as an image named <relative path without .txt>.png (no size: KITTI files have
// none). Throws std::runtime_error naming the file and line.
std::vector<ExchangeImage> readKittiLabelFiles(const std::filesystem::path& dir,
                                               const LabelClassTable& table);

}  // namespace fusedet::fusion
