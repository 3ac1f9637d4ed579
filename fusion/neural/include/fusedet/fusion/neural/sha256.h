// SPDX-License-Identifier: Apache-2.0
#pragma once
// SHA-256 (FIPS 180-4) of bytes and of files: the identity of a network's model files.

#include <filesystem>
#include <span>
#include <string>

namespace fusedet::fusion {

// Lower-case hex digest of `bytes`.
std::string sha256Hex(std::span<const unsigned char> bytes);
// Lower-case hex digest of a file's contents. Throws std::runtime_error naming the file when it
// cannot be read.
std::string sha256File(const std::filesystem::path& file);

}  // namespace fusedet::fusion
