// SPDX-License-Identifier: Apache-2.0
#include "dataset_codec.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "fusedet/core/dataset.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::dataset_detail {
namespace fs = std::filesystem;

namespace {
constexpr double kU16Max = 65535.0;
constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

[[noreturn]] void fail(const fs::path& file, const std::string& what) {
  throw DatasetError(file.string() + ": " + what);
}
}  // namespace

std::string typeName(int depth) {
  switch (depth) {
    case CV_8U: return "u8";
    case CV_16U: return "u16";
    case CV_32F: return "f32";
    default: return "?";
  }
}

int depthOfType(std::string_view name) {
  if (name == "u8") return CV_8U;
  if (name == "u16") return CV_16U;
  if (name == "f32") return CV_32F;
  return -1;
}

double defaultQuantum(std::string_view layerName) {
  // Chosen below each sensor's own resolution: 2 mm range (LMS 291 and HDL-64E are ~1 cm),
  // 1/65535 remission, 360/65536 degrees of hue (8-bit colour gives >= 0.24 degree steps).
  if (layerName == layer::kDistance) return 0.002;
  if (layerName == layer::kRemission) return 1.0 / kU16Max;
  if (layerName == layer::kHue) return 360.0 / 65536.0;
  if (layerName == layer::kHueDistance) return 180.0 / kU16Max;
  return 0;  // unknown float layer: spread its own range over 16 bit
}

Quantised quantise(const cv::Mat& data, std::string_view layerName, const std::string& what) {
  Quantised q;
  if (data.depth() != CV_32F) {
    q.stored = data;  // 8- and 16-bit layers are stored as they are
    return q;
  }
  if (!cv::checkRange(data, true)) throw DatasetError(what + ": float layer holds NaN or infinity");
  double lo = 0, hi = 0;
  if (!data.empty()) cv::minMaxLoc(data, &lo, &hi);
  double quantum = defaultQuantum(layerName);
  // Offset 0 keeps "0 = invalid" exactly 0; a negative minimum moves it to a multiple of the step.
  double offset = 0;
  if (lo < 0) {
    const double step = quantum > 0 ? quantum : (hi - lo) / kU16Max;
    offset = step > 0 ? std::floor(lo / step) * step : lo;
  }
  const double needed = (hi - offset) / kU16Max;
  q.scale = std::max(quantum, needed);
  if (!(q.scale > 0)) q.scale = 1;  // constant layer: any step represents it exactly
  q.offset = offset;
  q.stored.create(data.size(), CV_16UC1);
  const double inv = 1.0 / q.scale;
  for (int y = 0; y < data.rows; ++y) {
    const float* in = data.ptr<float>(y);
    std::uint16_t* out = q.stored.ptr<std::uint16_t>(y);
    for (int x = 0; x < data.cols; ++x) {
      const double v = std::round((static_cast<double>(in[x]) - offset) * inv);
      out[x] = static_cast<std::uint16_t>(std::clamp(v, 0.0, kU16Max));
    }
  }
  return q;
}

cv::Mat dequantise(const cv::Mat& stored, int depth, double scale, double offset) {
  if (depth != CV_32F) return stored;
  cv::Mat out;
  stored.convertTo(out, CV_32F, scale, offset);
  return out;
}

std::vector<unsigned char> readBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open (" + std::string(std::strerror(errno)) + ")");
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) fail(file, "cannot determine size");
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) fail(file, "read error");
  return bytes;
}

void writeBytesAtomic(const fs::path& file, const void* data, std::size_t size) {
  const fs::path tmp = file.string() + ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) fail(tmp, "cannot create (" + std::string(std::strerror(errno)) + ")");
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.flush();
    if (!out) fail(tmp, "write failed (disk full?)");
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) {
    fs::remove(tmp, ec);
    fail(file, "cannot replace: " + ec.message());
  }
}

void writePng(const fs::path& file, const cv::Mat& image) {
  std::vector<unsigned char> buf;
  if (!cv::imencode(".png", image, buf)) fail(file, "PNG encoding failed");
  writeBytesAtomic(file, buf.data(), buf.size());
}

cv::Mat readPng(const fs::path& file, int depth, int width, int height) {
  const std::vector<unsigned char> bytes = readBytes(file);
  if (bytes.size() < sizeof kPngSignature || std::memcmp(bytes.data(), kPngSignature, sizeof kPngSignature) != 0)
    fail(file, "not a PNG file (bad signature)");
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    fail(file, std::string("PNG decoding failed: ") + e.what());
  }
  if (image.empty()) fail(file, "corrupt or truncated PNG (cannot decode)");
  if (image.channels() != 1)
    fail(file, "has " + std::to_string(image.channels()) + " channels, expected 1 (grey)");
  const int want = depth == CV_8U ? CV_8U : CV_16U;
  if (image.depth() != want)
    fail(file, std::string("is ") + (image.depth() == CV_8U ? "8" : "16") + "-bit, expected " +
                   (want == CV_8U ? "8" : "16") + "-bit");
  if (image.cols != width || image.rows != height)
    fail(file, "is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                   ", item.json says " + std::to_string(width) + "x" + std::to_string(height));
  return image;
}

}  // namespace fusedet::dataset_detail
