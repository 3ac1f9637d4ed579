# SPDX-License-Identifier: Apache-2.0
# Calibration: camera intrinsics and targetless refinement from perturbed starts on KITTI, errors against the calib
# (timed CLI, not Google Benchmark). Its ctest run is issue 17's acceptance run with the defaults
# (10 trials, 10 frames, starts 1-2 deg / 5-10 cm off): it prints the error table and exits 1 when a
# median error exceeds 0.3 deg / 3 cm. About 30 s CPU; see README.md.
fusedet_bench(bench_calib_kitti SOURCES calib_kitti_bench.cpp DEPS fusedet_calibration CLI11::CLI11
              SMOKE_ARGS --trials 10 --frames 10 --max-rotation-deg 0.3 --max-translation 0.03)
# Issue 33: calibration on drives it was never tuned on, per-axis errors against the reported
# 1-sigma (README.md has the measured table). The smoke run is one trial of 3 frames.
fusedet_bench(bench_calib_heldout SOURCES calib_heldout_bench.cpp DEPS fusedet_calibration fusedet_datasets CLI11::CLI11
              SMOKE_ARGS --trials 1 --min-frames 3 --max-frames 3)
# Camera intrinsics from chessboard photographs (fusedet calibrate-camera) beside cv::calibrateCamera
# on the same corners of opencv-doc's sample photographs (README.md has the table).
fusedet_bench(bench_camera_intrinsics SOURCES camera_intrinsics_bench.cpp DEPS fusedet_calibration opencv_calib3d CLI11::CLI11
              SMOKE_ARGS --repeats 1)
# Issue 33: KITTI's sweeps as recorded and de-skewed by the car's motion during the Velodyne's turn,
# edge-measure peaks per frame and calibration trials on both (README.md has the table).
fusedet_bench(bench_calib_deskew SOURCES calib_deskew_bench.cpp DEPS fusedet_calibration fusedet_datasets CLI11::CLI11
              SMOKE_ARGS --every 13 --trials 1 --min-frames 3 --max-frames 3)
