# SPDX-License-Identifier: Apache-2.0
# The tracker after detection: one stack's update (prediction, gated optimal assignment, Kalman
# corrections, births and deaths) at 10, 50 and 200 objects; budget 1 ms per stack at 50 (issue 35).
fusedet_bench(bench_tracking SOURCES tracking_bench.cpp DEPS fusedet_tracking)
