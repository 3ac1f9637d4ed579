// SPDX-License-Identifier: Apache-2.0
// assign() against brute force over every partial matching, on worked examples and random
// matrices with forbidden pairs.
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "fusedet/tracking/assignment.h"

using fusedet::tracking::assign;
using fusedet::tracking::assignmentCost;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// Minimum of the objective over every partial matching (recursion over rows).
double bruteForce(const Eigen::MatrixXd& c, double unassigned, int row, std::vector<char>& colUsed) {
  if (row == c.rows()) {
    double rest = 0;
    for (char u : colUsed) rest += u ? 0 : unassigned;
    return rest;
  }
  double best = unassigned + bruteForce(c, unassigned, row + 1, colUsed);
  for (int j = 0; j < c.cols(); ++j) {
    if (colUsed[static_cast<std::size_t>(j)] || !std::isfinite(c(row, j))) continue;
    colUsed[static_cast<std::size_t>(j)] = 1;
    best = std::min(best, c(row, j) + bruteForce(c, unassigned, row + 1, colUsed));
    colUsed[static_cast<std::size_t>(j)] = 0;
  }
  return best;
}
double bruteForce(const Eigen::MatrixXd& c, double unassigned) {
  std::vector<char> used(static_cast<std::size_t>(c.cols()), 0);
  return bruteForce(c, unassigned, 0, used);
}
}  // namespace

TEST(Assignment, WorkedExampleGlobalBeatsGreedy) {
  // Greedy takes (0,0) = 1 and then (1,1) = 10: 11. Optimal: (0,1) + (1,0) = 2 + 3 = 5.
  Eigen::MatrixXd c(2, 2);
  c << 1, 2, 3, 10;
  EXPECT_EQ(assign(c, 100), (std::vector<int>{1, 0}));
}

TEST(Assignment, GateLeavesPairsUnassigned) {
  // Row 1's only pair costs 9 > 2 x 4 (both sides unassigned): it stays unassigned.
  Eigen::MatrixXd c(2, 2);
  c << 1, kInf, kInf, 9;
  EXPECT_EQ(assign(c, 4), (std::vector<int>{0, -1}));
  EXPECT_EQ(assign(c, 5), (std::vector<int>{0, 1}));
}

TEST(Assignment, RectangularAndEmpty) {
  Eigen::MatrixXd c(1, 3);
  c << 5, 1, 3;
  EXPECT_EQ(assign(c, 10), (std::vector<int>{1}));
  EXPECT_TRUE(assign(Eigen::MatrixXd(0, 4), 1).empty());
  EXPECT_EQ(assign(Eigen::MatrixXd(3, 0), 1), (std::vector<int>{-1, -1, -1}));
  Eigen::MatrixXd forbidden = Eigen::MatrixXd::Constant(2, 2, kInf);
  EXPECT_EQ(assign(forbidden, 1), (std::vector<int>{-1, -1}));
  EXPECT_THROW(assign(c, kInf), std::invalid_argument);
}

TEST(Assignment, MaximisesSimilarityWithZeroUnassignedCost) {
  Eigen::MatrixXd sim(3, 3);
  sim << 0.9, 0.8, 0, 0.85, 0, 0, 0, 0.6, 0.7;
  Eigen::MatrixXd c = -sim;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (sim(i, j) == 0) c(i, j) = kInf;
  // 0.8 + 0.85 + 0.7 = 2.35 beats 0.9 + 0.6 (+ row 1 alone) = 1.5.
  EXPECT_EQ(assign(c, 0), (std::vector<int>{1, 0, 2}));
}

TEST(Assignment, MatchesBruteForceOnRandomMatrices) {
  std::mt19937 rng(35);
  std::uniform_real_distribution<double> value(-1, 10);
  std::uniform_int_distribution<int> size(0, 6);
  std::bernoulli_distribution forbid(0.3);
  for (int trial = 0; trial < 2000; ++trial) {
    const int rows = size(rng), cols = size(rng);
    Eigen::MatrixXd c(rows, cols);
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) c(i, j) = forbid(rng) ? kInf : value(rng);
    const double unassigned = std::uniform_real_distribution<double>(0, 6)(rng);
    const std::vector<int> got = assign(c, unassigned);
    ASSERT_EQ(got.size(), static_cast<std::size_t>(rows));
    ASSERT_NEAR(assignmentCost(c, unassigned, got), bruteForce(c, unassigned), 1e-9) << "trial " << trial;
  }
}

TEST(Assignment, LargeSparseProblemIsOptimalPerComponent) {
  // 60 x 60 with a block structure of 3 x 3 blocks: the optimum is the sum of the blocks' optima.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(0, 5);
  Eigen::MatrixXd c = Eigen::MatrixXd::Constant(60, 60, kInf);
  double expected = 0;
  for (int b = 0; b < 20; ++b) {
    Eigen::MatrixXd block(3, 3);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) block(i, j) = value(rng);
    c.block(3 * b, 3 * b, 3, 3) = block;
    expected += bruteForce(block, 2.0);
  }
  EXPECT_NEAR(assignmentCost(c, 2.0, assign(c, 2.0)), expected, 1e-9);
}
