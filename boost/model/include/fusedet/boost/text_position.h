// SPDX-License-Identifier: Apache-2.0
#pragma once
// "line L, column C" of a byte offset in a text: where a parser's error points (model and
// outcomes files).

#include <cstddef>
#include <string>

namespace fusedet::boosting {

std::string lineColumn(const std::string& text, std::size_t byte);

}  // namespace fusedet::boosting
