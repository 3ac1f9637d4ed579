# SPDX-License-Identifier: Apache-2.0
# Detection engine: our detector vs cv::CascadeClassifier on the same cascade, images and scales,
# single thread, plus the cost per weak classifier on a 7-layer KITTI-size stack.
fusedet_bench(bench_detect_vs_opencv SOURCES detect_vs_opencv.cpp
              DEPS fusedet_boost_detect opencv_objdetect opencv_imgcodecs opencv_imgproc opencv_core
              SMOKE_ARGS --benchmark_min_time=0)
# All three bundled classes on one real fused KITTI stack in one pass, vs the previous per-class path
# and cv::CascadeClassifier (frontalface_default) on the same stack's intensity layer; with neural
# rows, each network's run and score layers on the same stack.
fusedet_bench(bench_detect3 SOURCES detect3_bench.cpp
              DEPS fusedet_boost_detect fusedet_datasets fusedet_neural opencv_objdetect opencv_core CLI11::CLI11
              SMOKE_ARGS --smoke)
# With neural rows: both networks from ../shared/models (YOLOv5n is AGPL-3.0: read there, never copied).
target_compile_definitions(bench_detect3 PRIVATE FUSEDET_MODELS_DIR="${PROJECT_SOURCE_DIR}/models"
                                                 FUSEDET_NETWORKS_DIR="${FUSEDET_NETWORKS_DIR}")
