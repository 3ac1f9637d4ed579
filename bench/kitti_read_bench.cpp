// SPDX-License-Identifier: Apache-2.0
// Reading one KITTI frame (PNG + 1.9 MB Velodyne + calib + labels) vs the PNG decode alone, the
// peer that bounds what the frame reader can cost.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "fusedet/fusion/datasets/kitti.h"

#include "headline_reporter.h"

namespace {
const std::filesystem::path kRoot = std::filesystem::path(FUSEDET_DATA_DIR) / "kitti";

void BM_ReadKittiFrame(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(fusedet::fusion::readKittiFrame(kRoot, "000000"));
}
BENCHMARK(BM_ReadKittiFrame)->Unit(benchmark::kMillisecond);

void BM_OpenCvImreadOnly(benchmark::State& state) {
  const auto png = (kRoot / "image_2" / "000000.png").string();
  for (auto _ : state) benchmark::DoNotOptimize(cv::imread(png, cv::IMREAD_COLOR));
}
BENCHMARK(BM_OpenCvImreadOnly)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  fusedet::bench::HeadlineReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const double ours = reporter.wall["BM_ReadKittiFrame"], png = reporter.wall["BM_OpenCvImreadOnly"];
  std::printf("bench: kitti_read_ms %.3f\n", ours);
  std::printf("bench: kitti_read_vs_png_decode %.3f\n", png > 0 ? ours / png : 0.0);
  return 0;
}
