// SPDX-License-Identifier: Apache-2.0
#pragma once
// A printed chessboard target: its inner-corner grid and where the corners are in a photograph.

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace fusedet::fusion {

// Inner corners per row (cols) and per column (rows), and the side of one square in metres.
struct BoardSpec {
  int cols = 9, rows = 6;
  double squareM = 0.025;
};

// "9x6" -> cols 9, rows 6; throws std::invalid_argument naming the text (each at least 3: a 2-wide
// grid has no corner the detector can order).
BoardSpec parseBoardSize(const std::string& text, double squareM);

// The corners on the board's plane (z = 0), row by row from the first detected corner, in metres:
// the order the detector reports them in.
std::vector<cv::Point3f> boardPoints(const BoardSpec& board);

// Every inner corner of the board in a grey image, refined to a tenth of a pixel or better, in
// boardPoints' order; nothing when the whole grid is not found (a partly hidden board is no view).
// Detection is OpenCV's chessboard detector (calib3d), refined with cv::cornerSubPix.
std::optional<std::vector<cv::Point2f>> findBoardCorners(const cv::Mat& gray, const BoardSpec& board);

// The same for an image file; throws std::runtime_error naming a file that does not decode.
std::optional<std::vector<cv::Point2f>> findBoardCorners(const std::filesystem::path& image, const BoardSpec& board,
                                                         cv::Size* imageSize);

}  // namespace fusedet::fusion
