# SPDX-License-Identifier: Apache-2.0
# The daemon: sensor stamp -> socket client latency replaying a synthesised KITTI sensor log at
# recorded speed, beside the pure compute of the same stacks.
fusedet_bench(bench_daemon_latency SOURCES daemon_latency_bench.cpp DEPS fusedet_daemon fusedet_synthesis fusedet_datasets CLI11::CLI11
              SMOKE_ARGS --frames 2 --passes 1)
target_compile_definitions(bench_daemon_latency PRIVATE FUSEDET_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
