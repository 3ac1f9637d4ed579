// SPDX-License-Identifier: Apache-2.0
// Which physical object a KITTI tracking label is: a hand-written file, garbage, and the shared
// drive 0005, whose SOURCE.md states that its cyclist is one track in every frame.

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

#include "fusedet/fusion/datasets/kitti.h"
#include "fusedet/fusion/datasets/kitti_tracks.h"

namespace fusedet::fusion {
namespace {

Label label(std::string source, Box box) {
  Label l;
  l.sourceClass = std::move(source);
  l.box = box;
  return l;
}

TEST(KittiTracks, LabelsFindTheirTrackByClassAndBox) {
  const KittiTracks t = parseKittiTracks(
      "0 -1 DontCare -1 -1 -10 219.31 188.49 245.5 218.56 -1000 -1000 -1000 -10 -1 -1 -1\n"
      "0 1 Cyclist 0 0 -1.9 737.619499 161.531951 931.112229 374.0 1.7 0.8 1.8 1.6 1.7 5.8 -1.7\n"
      "\n"
      "3 1 Cyclist 0 0 -1.9 740 160 930 374 1.7 0.8 1.8 1.6 1.7 5.8 -1.7\n"
      "3 7 Car 1 2 0.1 10 20 110 80 1.5 1.6 3.9 1 1 20 0\n");
  ASSERT_EQ(t.frames.size(), 2u);
  EXPECT_EQ(t.frames.at(3).size(), 2u);
  // Box x, y, w, h: the corners 737.619499..931.112229 x 161.531951..374.
  EXPECT_EQ(t.trackOf(0, label("Cyclist", {737.619499, 161.531951, 931.112229 - 737.619499, 374 - 161.531951})), 1);
  EXPECT_EQ(t.trackOf(0, label("Cyclist", {737.64, 161.531951, 193.49, 212.47})), -1);  // 0.02 px off
  EXPECT_EQ(t.trackOf(3, label("Car", {10, 20, 100, 60})), 7);
  EXPECT_EQ(t.trackOf(3, label("Van", {10, 20, 100, 60})), -1);        // another class
  EXPECT_EQ(t.trackOf(4, label("Car", {10, 20, 100, 60})), -1);        // another frame
  EXPECT_EQ(t.trackOf(0, label("DontCare", {219.31, 188.49, 26.19, 30.07})), -1);  // no object
  const auto ids = t.objectIds("d5", 3, {label("Car", {10, 20, 100, 60}), label("Cyclist", {740, 160, 190, 214}),
                                         label("Car", {0, 0, 5, 5})});
  EXPECT_EQ(ids, (std::vector<std::string>{"d5/track 7", "d5/track 1", ""}));
}

TEST(KittiTracks, MalformedLinesAreNamedNotGuessed) {
  for (const char* bad : {"0 1 Car", "x 1 Car 0 0 0 1 2 3 4", "0 1 Car 0 0 0 5 5 1 1", "-1 1 Car 0 0 0 1 2 3 4",
                          "0 -2 Car 0 0 0 1 2 3 4", "0 1 Car 0 0 0 nan 2 3 4", "\x01\x02\x03",
                          // finite corners whose width (or height) overflows to inf (issue 37)
                          "0 1 Car 0 0 0 -1e308 2 1e308 4", "0 1 Car 0 0 0 1 -1.7e308 3 1.7e308"}) {
    try {
      parseKittiTracks(std::string(bad) + "\n", "t.txt");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("t.txt: line 1"), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(parseKittiTracks("").frames.empty());
  EXPECT_TRUE(readKittiTracks(std::filesystem::temp_directory_path() / "no-such-kitti-dir").frames.empty());
}

TEST(KittiTracks, SharedDrive0005HasOneCyclist) {
  const std::filesystem::path root = std::filesystem::path(FUSEDET_DATA_DIR) / "kitti";
  if (!std::filesystem::exists(root / "tracking_label_02_0000.txt")) GTEST_SKIP() << "no shared data";
  const KittiTracks t = readKittiTracks(root);
  std::set<std::string> cyclists;
  std::size_t cyclistLabels = 0;
  for (const std::string& id : listKittiFrames(root)) {
    const Labels labels = readKittiLabels(root / "label_2" / (id + ".txt"));
    const auto ids = t.objectIds("0005", std::stoi(id), labels);
    ASSERT_EQ(ids.size(), labels.size());
    for (std::size_t j = 0; j < labels.size(); ++j) {
      if (labels[j].sourceClass != "Cyclist") continue;
      ++cyclistLabels;
      EXPECT_FALSE(ids[j].empty()) << id;
      cyclists.insert(ids[j]);
    }
  }
  EXPECT_EQ(cyclistLabels, 52u);  // SOURCE.md: Cyclist 52 in these 52 frames
  EXPECT_EQ(cyclists.size(), 1u);  // "one cyclist, the same track in every frame"
}

}  // namespace
}  // namespace fusedet::fusion
