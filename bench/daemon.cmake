# SPDX-License-Identifier: Apache-2.0
# The daemon: sensor stamp -> socket client latency replaying a synthesised KITTI sensor log at
# recorded speed, beside the pure compute of the same stacks; with --viewers, the same with the
# live view on and 0, 1, 5, ... WebSocket viewers attached (live_viewers.cpp); with --neural, the
# same with neural layers on, per network.
fusedet_bench(bench_daemon_latency SOURCES daemon_latency_bench.cpp live_viewers.cpp
              DEPS fusedet_daemon fusedet_synthesis fusedet_datasets CLI11::CLI11 Boost::headers
              SMOKE_ARGS --frames 2 --passes 1 --viewers 1 --neural darknet,yolov5-onnx)
target_compile_options(bench_daemon_latency PRIVATE ${FUSEDET_ASIO_OPTIONS})
# --neural: the networks from ../shared/models (YOLOv5n is AGPL-3.0: read there, never copied).
target_compile_definitions(bench_daemon_latency PRIVATE FUSEDET_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                                        FUSEDET_NETWORKS_DIR="${FUSEDET_NETWORKS_DIR}")
