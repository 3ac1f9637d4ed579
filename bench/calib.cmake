# Calibration: targetless refinement from perturbed starts on KITTI, errors against the calib
# (timed CLI, not Google Benchmark). The smoke run (2 trials, 4 frames) prints the error table and
# only catches a broken pipeline (median error within 3 deg / 0.3 m); the acceptance run is
# `bench_calib_kitti` with its defaults (10 trials, 10 frames, 0.3 deg / 3 cm), see README.md.
fusedet_bench(bench_calib_kitti SOURCES calib_kitti_bench.cpp DEPS fusedet_fusion CLI11::CLI11
              SMOKE_ARGS --trials 2 --frames 4 --max-rotation-deg 3 --max-translation 0.3)
