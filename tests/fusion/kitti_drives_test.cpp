// SPDX-License-Identifier: Apache-2.0
// Raw drives from SOURCE.md: a hand-written example of both forms, garbage, and the shared data's
// own files (their counts are stated in those files).

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "fusedet/fusion/datasets/kitti.h"
#include "fusedet/fusion/datasets/kitti_drives.h"

namespace fusedet::fusion {
namespace {

TEST(KittiDrives, HeadingAndTable) {
  const KittiDriveMap m = parseKittiDriveMap(
      "# KITTI drive 2011_09_26_drive_0005 = tracking 0000\n"
      "text mentioning 2011_09_26_drive_0101 is not a heading\n"
      "| id | image | raw drive | raw frame |\n"
      "| --- | --- | --- | --- |\n"
      "| 000010 | 1242x375 | 2011_09_26_drive_0036 | 151 |\n"
      "| 000015 | 1238x374 | 2011_09_29_drive_0071 | 421 |\n"
      "\n"
      "| id | objects |\n| 000099 | 2011_09_26_drive_0001 |\n");
  EXPECT_EQ(m.directoryDrive, "2011_09_26_drive_0005");
  EXPECT_EQ(m.driveOf("000010", "x"), "2011_09_26_drive_0036");
  EXPECT_EQ(m.driveOf("000015", "x"), "2011_09_29_drive_0071");
  EXPECT_EQ(m.driveOf("000099", "x"), "2011_09_26_drive_0005");  // that table has no raw drive column
  EXPECT_EQ(parseKittiDriveMap("").driveOf("1", "fallback"), "fallback");
  for (const char* junk : {"|", "||||", "| id | raw drive |\n| 1 |", "# \x01\x02 drive_", "| id | raw drive |\n|a|b|c|"})
    EXPECT_NO_THROW(parseKittiDriveMap(junk));
}

TEST(KittiDrives, SharedDataHas22Drives) {
  const std::filesystem::path root(FUSEDET_DATA_DIR);
  if (!std::filesystem::is_directory(root / "kitti_object_more")) GTEST_SKIP() << "no shared data";
  std::set<std::string> drives;
  std::size_t frames = 0;
  for (const char* dir : {"kitti", "kitti_0009", "kitti_object_sample", "kitti_object_more"}) {
    const KittiDriveMap m = readKittiDriveMap(root / dir);
    for (const std::string& id : listKittiFrames(root / dir)) {
      const std::string d = m.driveOf(id, "");
      EXPECT_FALSE(d.empty()) << dir << "/" << id;
      drives.insert(d);
      ++frames;
    }
  }
  // SOURCE.md files: 0005, 0009; 18 drives in kitti_object_more; 0106 and 0086 new in the sample
  // (its 000001 shares drive 0101 with kitti_object_more/000023).
  EXPECT_EQ(drives.size(), 22u);
  EXPECT_TRUE(drives.count("2011_09_26_drive_0101"));
  EXPECT_EQ(readKittiDriveMap(root / "kitti_object_more").driveOf("000023", ""), "2011_09_26_drive_0101");
  EXPECT_EQ(readKittiDriveMap(root / "kitti_object_sample").driveOf("000001", ""), "2011_09_26_drive_0101");
  EXPECT_GT(frames, 100u);
}

}  // namespace
}  // namespace fusedet::fusion
