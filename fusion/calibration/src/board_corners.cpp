// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/board_corners.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusedet::fusion {

BoardSpec parseBoardSize(const std::string& text, double squareM) {
  BoardSpec b;
  b.squareM = squareM;
  char x = 0;
  std::size_t used = 0;
  try {
    b.cols = std::stoi(text, &used);
    x = used < text.size() ? text[used] : 0;
    std::size_t more = 0;
    b.rows = std::stoi(text.substr(used + 1), &more);
    used += 1 + more;
  } catch (const std::exception&) {
    x = 0;
  }
  if (x != 'x' || used != text.size() || b.cols < 3 || b.rows < 3)
    throw std::invalid_argument("board '" + text + "': expected inner corners as COLSxROWS, each 3 or more (e.g. 9x6)");
  if (!(squareM > 0)) throw std::invalid_argument("board square size must be > 0 m");
  return b;
}

std::vector<cv::Point3f> boardPoints(const BoardSpec& board) {
  std::vector<cv::Point3f> points;
  points.reserve(static_cast<std::size_t>(board.cols * board.rows));
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.cols; ++c)
      points.emplace_back(static_cast<float>(c * board.squareM), static_cast<float>(r * board.squareM), 0.0f);
  return points;
}

std::optional<std::vector<cv::Point2f>> findBoardCorners(const cv::Mat& gray, const BoardSpec& board) {
  std::vector<cv::Point2f> corners;
  const cv::Size grid(board.cols, board.rows);
  if (!cv::findChessboardCorners(gray, grid, corners, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
    return std::nullopt;
  // The detector's corners are vertices of thresholded quads (about a pixel off); the saddle point
  // of the grey values in a 23 x 23 window around each gives the accuracy calibration needs.
  cv::cornerSubPix(gray, corners, cv::Size(11, 11), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 50, 1e-3));
  return corners;
}

std::optional<std::vector<cv::Point2f>> findBoardCorners(const std::filesystem::path& image, const BoardSpec& board,
                                                         cv::Size* imageSize) {
  const cv::Mat gray = cv::imread(image.string(), cv::IMREAD_GRAYSCALE);
  if (gray.empty()) throw std::runtime_error(image.string() + ": not an image OpenCV can read");
  if (imageSize) *imageSize = gray.size();
  return findBoardCorners(gray, board);
}

}  // namespace fusedet::fusion
