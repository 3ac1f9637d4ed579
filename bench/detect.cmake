# Detection engine: our detector vs cv::CascadeClassifier on the same cascade, images and scales,
# single thread, plus the cost per weak classifier on a 7-layer KITTI-size stack.
fusedet_bench(bench_detect_vs_opencv SOURCES detect_vs_opencv.cpp
              DEPS fusedet_boost opencv_objdetect opencv_imgcodecs opencv_imgproc opencv_core
              SMOKE_ARGS --benchmark_min_time=0)
