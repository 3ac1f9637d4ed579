// SPDX-License-Identifier: Apache-2.0
#pragma once
// Optimal assignment (Kuhn-Munkres / Hungarian method with potentials, O(n^3)) of rows to columns
// of a cost matrix, where a row or column may also stay unassigned at a fixed price: the tracker's
// track-to-detection association (gated Mahalanobis distances) and the MOT metrics' matching.

#include <Eigen/Core>
#include <vector>

namespace fusedet::tracking {

// Pairs (row, column) with a finite cost are allowed; +infinity (or NaN) forbids a pair. Returns,
// per row, its column or -1, minimising  sum of the chosen pairs' costs + unassignedCost x (rows
// left unassigned + columns left unassigned). E.g. unassignedCost = gate / 2 makes every allowed
// pair worth taking on its own; unassignedCost = 0 with costs = -similarity maximises the summed
// similarity over the allowed pairs. Rows and columns that share no allowed pair are solved
// apart (connected components), so sparse gates stay cheap. Ties are broken deterministically.
std::vector<int> assign(const Eigen::MatrixXd& cost, double unassignedCost);

// The objective assign() minimises, for a given row -> column map (-1 = unassigned); +infinity
// when it uses a forbidden pair.
double assignmentCost(const Eigen::MatrixXd& cost, double unassignedCost, const std::vector<int>& rowToColumn);

}  // namespace fusedet::tracking
