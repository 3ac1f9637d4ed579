// SPDX-License-Identifier: Apache-2.0
#pragma once
// Short texts of numbers and lists shared by the experiments' output.

#include <string>
#include <vector>

namespace fusedet::tools::experiments {

std::string shortNum(double v);

std::string joined(const std::vector<std::string>& v, const std::string& sep = ", ");

std::string foldsText(std::size_t folds, std::size_t drives);

std::string learningText(const std::vector<std::size_t>& counts, const std::string& sep = ", ");

}  // namespace fusedet::tools::experiments
