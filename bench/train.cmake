# SPDX-License-Identifier: Apache-2.0
# Training benchmarks (boost/ training half). bench_boost_round: one boosting round on the issue's
# reference matrix (OpenCV's default pool on KITTI windows), ours vs XGBoost (hist) vs cv::ml::Boost;
# the ctest smoke run uses a tiny matrix from 3 frames per drive.
# Debian's XGBoostConfig.cmake names /usr/bin/xgboost, which libxgboost-dev does not ship, so the
# library is found directly.
find_library(FUSEDET_XGBOOST_LIB NAMES xgboost REQUIRED)
find_path(FUSEDET_XGBOOST_INCLUDE xgboost/c_api.h REQUIRED)
fusedet_bench(bench_boost_round SOURCES boost_round_bench.cpp
              DEPS fusedet_boost_train fusedet_datasets ${FUSEDET_XGBOOST_LIB} opencv_imgproc opencv_ml opencv_core TBB::tbb CLI11::CLI11
              SMOKE_ARGS --smoke)
target_include_directories(bench_boost_round SYSTEM PRIVATE ${FUSEDET_XGBOOST_INCLUDE})
