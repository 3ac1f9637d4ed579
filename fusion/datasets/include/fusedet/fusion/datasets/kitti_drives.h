// SPDX-License-Identifier: Apache-2.0
#pragma once
// The raw KITTI drive each frame of a KITTI-layout directory comes from, read from the
// directory's SOURCE.md, so that cross-drive validation keeps frames of one drive (the same
// street, the same cars) on one side of a split. Two forms are understood:
//  - a heading naming one drive for the whole directory ("# KITTI drive 2011_09_26_drive_0005 ...");
//  - a markdown table with an "id" column and a "raw drive" column (object-benchmark frames,
//    e.g. "| 000010 | 1242x375 | 2011_09_26_drive_0036 | 151 | ..."); a table row overrides the heading.

#include <filesystem>
#include <map>
#include <string>

namespace fusedet::fusion {

struct KittiDriveMap {
  std::string directoryDrive;                 // from the heading; empty when none
  std::map<std::string, std::string> frames;  // frame id -> drive, from tables

  // The frame's drive, else the directory's, else `fallback`.
  std::string driveOf(const std::string& frameId, const std::string& fallback) const;
};

// Parses SOURCE.md text. Lines that fit neither form are skipped; never throws.
KittiDriveMap parseKittiDriveMap(const std::string& markdown);
// SOURCE.md of `root`; an empty map when the file does not exist.
KittiDriveMap readKittiDriveMap(const std::filesystem::path& root);

}  // namespace fusedet::fusion
