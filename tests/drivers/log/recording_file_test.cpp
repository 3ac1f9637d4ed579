// SPDX-License-Identifier: Apache-2.0
// createRecordingFile (`fusedet record --out-dir`): the UTC start time names the file, a second
// start in the same second gets its own file, an existing recording is never truncated, and a
// folder that cannot take a file is an error naming it.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "fusedet/drivers/log/recording_file.h"

namespace fs = std::filesystem;
using namespace std::chrono;
using fusedet::drivers::logs::createRecordingFile;

namespace {
fs::path freshDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}
std::string content(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::string s;
  std::getline(in, s);
  return s;
}
// 2026-12-02 07:15:09.750 UTC
const system_clock::time_point kStart = sys_days{year{2026} / December / 2} + hours(7) + minutes(15) + seconds(9) + milliseconds(750);
}  // namespace

TEST(RecordingFile, NamedByUtcStartAndNeverReused) {
  const fs::path d = freshDir("fusedet-recording-file");
  const fs::path first = createRecordingFile(d, kStart);
  EXPECT_EQ(first, d / "fusedet-20261202T071509Z.mcap");
  EXPECT_TRUE(fs::is_regular_file(first));
  EXPECT_EQ(fs::file_size(first), 0u);
  // The first start's recording has data; a restart within the same second must not touch it.
  std::ofstream(first, std::ios::binary) << "recorded";
  const fs::path second = createRecordingFile(d, kStart + milliseconds(100));
  EXPECT_EQ(second, d / "fusedet-20261202T071509Z-2.mcap");
  EXPECT_EQ(content(first), "recorded");
  EXPECT_EQ(createRecordingFile(d, kStart), d / "fusedet-20261202T071509Z-3.mcap");
  // The next second is a name of its own again; names sort in time order.
  const fs::path later = createRecordingFile(d, kStart + seconds(1));
  EXPECT_EQ(later, d / "fusedet-20261202T071510Z.mcap");
  EXPECT_LT(first.filename().string(), later.filename().string());
  fs::remove_all(d);
}

TEST(RecordingFile, MissingFolderIsNamed) {
  const fs::path d = freshDir("fusedet-recording-file-missing") / "not-there";
  try {
    createRecordingFile(d, kStart);
    FAIL() << "no error for a missing folder";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(d.string()), std::string::npos) << what;
    EXPECT_NE(what.find("No such file or directory"), std::string::npos) << what;
  }
  fs::remove_all(d.parent_path());
}
