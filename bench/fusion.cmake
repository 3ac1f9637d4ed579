# SPDX-License-Identifier: Apache-2.0
# Fusion: one KITTI frame fused into a layer stack, per-step breakdown, vs a stock-OpenCV pipeline.
fusedet_bench(bench_kitti_fuse SOURCES kitti_fuse_bench.cpp
              DEPS fusedet_datasets ${OpenCV_LIBS} opencv_calib3d
              SMOKE_ARGS --benchmark_min_time=0)
