// SPDX-License-Identifier: Apache-2.0
#pragma once
// A new recording's file in a folder of recordings (`fusedet record --out-dir`, the packaged
// fusedet-record.service): named by the UTC time recording starts, fusedet-YYYYMMDDTHHMMSSZ.mcap,
// so a listing sorts in time order and every start (a restart, a crash's Restart=) gets a file
// of its own. The file is created exclusively (O_EXCL): an existing recording is never reopened
// or truncated; a second start within the same second gets "-2", "-3", ... before ".mcap".

#include <chrono>
#include <filesystem>

namespace fusedet::drivers::logs {

// Creates the file (empty, mode 0666 less the umask) and returns its path. Throws
// std::runtime_error naming the folder and the reason (missing, not writable, full, or 100
// files of the same second).
std::filesystem::path createRecordingFile(const std::filesystem::path& dir, std::chrono::system_clock::time_point start);

}  // namespace fusedet::drivers::logs
