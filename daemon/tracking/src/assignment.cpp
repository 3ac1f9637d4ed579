// SPDX-License-Identifier: Apache-2.0
#include "fusedet/tracking/assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace fusedet::tracking {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool allowed(double c) { return std::isfinite(c); }

// Square minimum-cost perfect matching (Hungarian method with row and column potentials, one
// augmenting path per row, 1-based internally). a: n x n, +inf = forbidden; a perfect matching of
// finite entries must exist. Returns row -> column.
std::vector<int> hungarianSquare(const std::vector<double>& a, int n) {
  std::vector<double> u(n + 1, 0), v(n + 1, 0), minv(n + 1);
  std::vector<int> p(n + 1, 0), way(n + 1, 0);
  std::vector<char> used(n + 1);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::fill(minv.begin(), minv.end(), kInf);
    std::fill(used.begin(), used.end(), 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = kInf;
      int j1 = -1;
      for (int j = 1; j <= n; ++j) {
        if (used[j]) continue;
        const double cur = a[static_cast<std::size_t>((i0 - 1) * n + (j - 1))] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      if (j1 < 0 || !std::isfinite(delta)) throw std::logic_error("assign: no complete assignment (internal)");
      for (int j = 0; j <= n; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> rowToCol(n, -1);
  for (int j = 1; j <= n; ++j)
    if (p[j] > 0) rowToCol[p[j] - 1] = j - 1;
  return rowToCol;
}

// One connected component: rows R, columns C. The square problem of size |R| + |C|:
//   [ cost(R, C)            diag(unassigned) |R|x|R| ]
//   [ diag(unassigned) |C|x|C|   zeros |C|x|R|       ]
// A real row matched to its dummy column stays unassigned, a dummy row matched to a real column
// leaves that column unassigned; dummies pair up at no cost.
void solveComponent(const Eigen::MatrixXd& cost, double unassignedCost, const std::vector<int>& rows,
                    const std::vector<int>& cols, std::vector<int>& rowToColumn) {
  const int nr = static_cast<int>(rows.size()), nc = static_cast<int>(cols.size());
  const int n = nr + nc;
  std::vector<double> a(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), kInf);
  auto at = [&](int r, int c) -> double& { return a[static_cast<std::size_t>(r * n + c)]; };
  for (int r = 0; r < nr; ++r) {
    for (int c = 0; c < nc; ++c) {
      const double v = cost(rows[static_cast<std::size_t>(r)], cols[static_cast<std::size_t>(c)]);
      if (allowed(v)) at(r, c) = v;
    }
    at(r, nc + r) = unassignedCost;
  }
  for (int c = 0; c < nc; ++c) {
    at(nr + c, c) = unassignedCost;
    for (int r = 0; r < nr; ++r) at(nr + c, nc + r) = 0;
  }
  const std::vector<int> match = hungarianSquare(a, n);
  for (int r = 0; r < nr; ++r)
    if (match[static_cast<std::size_t>(r)] < nc)
      rowToColumn[static_cast<std::size_t>(rows[static_cast<std::size_t>(r)])] = cols[static_cast<std::size_t>(match[static_cast<std::size_t>(r)])];
}

}  // namespace

std::vector<int> assign(const Eigen::MatrixXd& cost, double unassignedCost) {
  if (!std::isfinite(unassignedCost)) throw std::invalid_argument("assign: the unassigned cost must be finite");
  const int rows = static_cast<int>(cost.rows()), cols = static_cast<int>(cost.cols());
  std::vector<int> rowToColumn(static_cast<std::size_t>(rows), -1);
  // Connected components of the allowed pairs (union-find over rows 0..rows-1, columns rows..).
  std::vector<int> parent(static_cast<std::size_t>(rows + cols));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
      x = parent[static_cast<std::size_t>(x)];
    }
    return x;
  };
  std::vector<char> rowHasPair(static_cast<std::size_t>(rows), 0), colHasPair(static_cast<std::size_t>(cols), 0);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if (allowed(cost(r, c))) {
        rowHasPair[static_cast<std::size_t>(r)] = colHasPair[static_cast<std::size_t>(c)] = 1;
        const int a = find(r), b = find(rows + c);
        if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      }
  std::vector<std::vector<int>> compRows(static_cast<std::size_t>(rows + cols)), compCols(static_cast<std::size_t>(rows + cols));
  for (int r = 0; r < rows; ++r)
    if (rowHasPair[static_cast<std::size_t>(r)]) compRows[static_cast<std::size_t>(find(r))].push_back(r);
  for (int c = 0; c < cols; ++c)
    if (colHasPair[static_cast<std::size_t>(c)]) compCols[static_cast<std::size_t>(find(rows + c))].push_back(c);
  for (std::size_t k = 0; k < compRows.size(); ++k)
    if (!compRows[k].empty()) solveComponent(cost, unassignedCost, compRows[k], compCols[k], rowToColumn);
  return rowToColumn;
}

double assignmentCost(const Eigen::MatrixXd& cost, double unassignedCost, const std::vector<int>& rowToColumn) {
  if (rowToColumn.size() != static_cast<std::size_t>(cost.rows()))
    throw std::invalid_argument("assignmentCost: one entry per row expected");
  std::vector<char> colUsed(static_cast<std::size_t>(cost.cols()), 0);
  double total = 0;
  for (std::size_t r = 0; r < rowToColumn.size(); ++r) {
    const int c = rowToColumn[r];
    if (c < 0) {
      total += unassignedCost;
      continue;
    }
    if (c >= cost.cols() || colUsed[static_cast<std::size_t>(c)]) throw std::invalid_argument("assignmentCost: column out of range or used twice");
    colUsed[static_cast<std::size_t>(c)] = 1;
    const double v = cost(static_cast<Eigen::Index>(r), c);
    if (!allowed(v)) return kInf;
    total += v;
  }
  for (char used : colUsed)
    if (!used) total += unassignedCost;
  return total;
}

}  // namespace fusedet::tracking
