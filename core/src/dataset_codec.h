// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal to the data set reader/writer: one layer <-> one PNG (quantisation of float layers),
// strict PNG and file I/O. Facts of the format: docs/dataset-format.md.

#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace fusedet::dataset_detail {

// In-memory type of a layer as the sidecar names it: "u8", "u16", "f32".
std::string typeName(int depth);
int depthOfType(std::string_view name);  // -1 if unknown

// How a layer is stored: the PNG pixels and the affine map value = offset + scale * stored.
struct Quantised {
  cv::Mat stored;  // CV_8UC1 (u8) or CV_16UC1 (u16, f32)
  double scale = 1;
  double offset = 0;
};

// Smallest step a float layer is stored with unless its values need a coarser one to fit 16 bit.
double defaultQuantum(std::string_view layerName);
// Throws DatasetError naming `what` if a float layer holds NaN or infinity.
Quantised quantise(const cv::Mat& data, std::string_view layerName, const std::string& what);
// Inverse of quantise(): the stored PNG back to the layer's in-memory depth.
cv::Mat dequantise(const cv::Mat& stored, int depth, double scale, double offset);

// Whole-file I/O; errors name the file.
std::vector<unsigned char> readBytes(const std::filesystem::path& file);
// Writes to a temporary sibling and renames, so a reader never sees half a file.
void writeBytesAtomic(const std::filesystem::path& file, const void* data, std::size_t size);

void writePng(const std::filesystem::path& file, const cv::Mat& image);
// Decodes a single-channel PNG of the given depth and size, or throws DatasetError naming the file
// and what is wrong (not a PNG, corrupt or truncated, wrong depth, channels or size).
cv::Mat readPng(const std::filesystem::path& file, int depth, int width, int height);

}  // namespace fusedet::dataset_detail
