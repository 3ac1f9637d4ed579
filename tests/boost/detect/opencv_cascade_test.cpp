// SPDX-License-Identifier: Apache-2.0
// OpenCV Haar XML import: a hand-written cascade read back field by field, every shipped
// stump cascade loads, bad files fail with the file name and the problem, and a fuzz run over
// mutated files never crashes or hangs.

#include "fusedet/boost/opencv_cascade.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

using namespace fusedet::boosting;
namespace fs = std::filesystem;

namespace {

const fs::path kCascades = "/usr/share/opencv4/haarcascades";

const std::string kSmall = R"(<?xml version="1.0"?>
<opencv_storage>
<cascade type_id="opencv-cascade-classifier"><stageType>BOOST</stageType>
  <featureType>HAAR</featureType>
  <height>20</height>
  <width>24</width>
  <stageParams><maxWeakCount>2</maxWeakCount></stageParams>
  <featureParams><maxCatCount>0</maxCatCount></featureParams>
  <stageNum>2</stageNum>
  <stages>
    <_>
      <maxWeakCount>2</maxWeakCount>
      <stageThreshold>-1.5</stageThreshold>
      <weakClassifiers>
        <_><internalNodes>0 -1 0 0.25</internalNodes><leafValues>-1. 1.</leafValues></_>
        <_><internalNodes>0 -1 1 -3.0e-02</internalNodes><leafValues>2.0e-06 0.5</leafValues></_></weakClassifiers></_>
    <_>
      <maxWeakCount>1</maxWeakCount>
      <stageThreshold>0.1</stageThreshold>
      <weakClassifiers>
        <_><internalNodes>0 -1 1 1.</internalNodes><leafValues>0.3 -0.7</leafValues></_></weakClassifiers></_></stages>
  <features>
    <_><rects><_>2 3 8 4 -1.</_><_>2 5 8 2 2.</_></rects></_>
    <_><rects><_>10 2 6 6 -1.</_><_>10 2 3 3 2.</_><_>13 5 3 3 2.</_></rects><tilted>0</tilted></_>
  </features>
</cascade>
</opencv_storage>
)";

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Expects parsing to fail with a message naming the source and containing `what`.
void expectError(const std::string& text, const std::string& what) {
  try {
    parseOpenCvCascade(text, "bad.xml");
    ADD_FAILURE() << "no error, expected: " << what;
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("bad.xml: ", 0), 0u) << m;
    EXPECT_NE(m.find(what), std::string::npos) << m;
  }
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

}  // namespace

TEST(OpenCvCascade, ReadsEveryFieldWithOpenCvsLoadConventions) {
  const Cascade c = parseOpenCvCascade(kSmall, "small.xml");
  EXPECT_EQ(c.className, "small");
  EXPECT_EQ(c.windowWidth, 24);
  EXPECT_EQ(c.windowHeight, 20);
  EXPECT_EQ(c.layers, std::vector<std::string>{"intensity"});
  EXPECT_TRUE(c.isOpenCv());
  ASSERT_EQ(c.stages.size(), 2u);
  ASSERT_EQ(c.stages[0].stumps.size(), 2u);
  // Stage thresholds lowered by OpenCV's 1e-5 in float; leaves below 1e-5 become 0.
  EXPECT_EQ(c.stages[0].threshold, double(-1.5f - 1e-5f));
  EXPECT_EQ(c.stages[1].threshold, double(0.1f - 1e-5f));
  EXPECT_EQ(c.stages[0].stumps[1].feature, 1);
  EXPECT_EQ(c.stages[0].stumps[1].threshold, double(-3.0e-02f));
  EXPECT_EQ(c.stages[0].stumps[1].left, 0.0);
  EXPECT_EQ(c.stages[0].stumps[1].right, 0.5);
  ASSERT_EQ(c.haarFeatures.size(), 2u);
  EXPECT_EQ(c.haarFeatures[0].count, 2);
  EXPECT_EQ(c.haarFeatures[1].count, 3);
  EXPECT_EQ(c.haarFeatures[1].rects[2].x, 13);
  EXPECT_EQ(c.haarFeatures[1].rects[2].weight, 2.f);
  EXPECT_FALSE(c.haarFeatures[1].tilted);
}

TEST(OpenCvCascade, LoadsEveryShippedCascadeStumpsAndTrees) {
  int loaded = 0, withTrees = 0;
  for (const auto& e : fs::directory_iterator(kCascades)) {
    const std::string name = e.path().filename().string();
    const bool trees = name.find("alt2") != std::string::npos || name.find("2splits") != std::string::npos ||
                       name.find("tree_eyeglasses") != std::string::npos;
    const Cascade c = loadOpenCvCascade(e.path());
    EXPECT_GT(c.stages.size(), 0u) << name;
    EXPECT_EQ(c.hasTrees(), trees) << name;
    withTrees += c.hasTrees();
    ++loaded;
  }
  EXPECT_EQ(withTrees, 4);
  EXPECT_GE(loaded, 16);
  const Cascade face = loadOpenCvCascade(kCascades / "haarcascade_frontalface_default.xml");
  EXPECT_EQ(face.stages.size(), 25u);
  EXPECT_EQ(face.weakCount(), 2913u);
  const Cascade plate = loadOpenCvCascade(kCascades / "haarcascade_licence_plate_rus_16stages.xml");  // old format
  EXPECT_EQ(plate.windowWidth, 64);
  EXPECT_EQ(plate.windowHeight, 16);
  EXPECT_EQ(plate.stages.size(), 16u);
  int tilted = 0;
  for (const HaarFeature& f : loadOpenCvCascade(kCascades / "haarcascade_fullbody.xml").haarFeatures) tilted += f.tilted;
  EXPECT_GT(tilted, 0);
}

TEST(OpenCvCascade, TruncatedXmlNamesTheFileAndTheProblem) {
  const std::string full = readFile(kCascades / "haarcascade_frontalface_default.xml");
  ASSERT_GT(full.size(), 1000u);
  expectError(full.substr(0, full.size() / 2), "truncated");
  expectError(kSmall.substr(0, kSmall.size() - 30), "missing </");
  expectError("", "no root element");
  const fs::path tmp = fs::temp_directory_path() / "fusedet_truncated_cascade.xml";
  std::ofstream(tmp) << full.substr(0, 5000);
  try {
    loadOpenCvCascade(tmp);
    ADD_FAILURE() << "truncated file loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(tmp.string()), std::string::npos) << e.what();
  }
  fs::remove(tmp);
  EXPECT_THROW(loadOpenCvCascade("/nonexistent/cascade.xml"), std::runtime_error);
}

TEST(OpenCvCascade, WrongCountsAreReported) {
  expectError(replaced(kSmall, "<stageNum>2</stageNum>", "<stageNum>3</stageNum>"), "stageNum says 3 stages");
  expectError(replaced(kSmall, "<maxWeakCount>1</maxWeakCount>", "<maxWeakCount>4</maxWeakCount>"),
              "maxWeakCount says 4");
  expectError(replaced(kSmall, "<leafValues>0.3 -0.7</leafValues>", "<leafValues>0.3</leafValues>"), "leaf values");
  expectError(replaced(kSmall, "0 -1 1 1.</internalNodes>", "0 -1 1</internalNodes>"), "4 numbers per node");
  expectError(replaced(kSmall, "0 -1 1 1.</internalNodes>", "0 -1 7 1.</internalNodes>"), "uses feature 7");
  expectError(replaced(kSmall, "<_>2 5 8 2 2.</_>", "<_>2 5 8 2</_>"), "x y width height weight");
  expectError(replaced(kSmall, "<_>2 3 8 4 -1.</_><_>2 5 8 2 2.</_>", "<_>2 3 8 4 -1.</_>"), "1 rectangles");
  expectError(replaced(kSmall, "<_>2 3 8 4 -1.</_>", "<_>20 3 8 4 -1.</_>"), "outside the 24x20 window");
  expectError(replaced(kSmall, "<_>2 3 8 4 -1.</_>", "<_>2 3 999999999 999999999 -1.</_>"), "outside the 24x20 window");
}

TEST(OpenCvCascade, TreesAreReadNodeByNodeAndBadChildrenRejected) {
  const std::string tree = replaced(kSmall, "<_><internalNodes>0 -1 1 1.</internalNodes><leafValues>0.3 -0.7</leafValues></_>",
                                    "<_><internalNodes>1 -1 1 1. 0 -2 0 2.5</internalNodes><leafValues>0.3 -0.7 0.1</leafValues></_>");
  const Cascade c = parseOpenCvCascade(tree, "tree.xml");
  ASSERT_TRUE(c.hasTrees());
  EXPECT_TRUE(c.stages[0].stumps.empty());
  ASSERT_EQ(c.treeStages.size(), 2u);
  ASSERT_EQ(c.treeStages[1].size(), 1u);
  const Tree& t = c.treeStages[1][0];
  ASSERT_EQ(t.nodes.size(), 2u);
  EXPECT_EQ(t.nodes[0].left, 1);
  EXPECT_EQ(t.nodes[0].right, -1);
  EXPECT_EQ(t.nodes[1].feature, 0);
  EXPECT_EQ(t.nodes[1].threshold, 2.5);
  EXPECT_EQ(t.leaves[2], double(0.1f));
  EXPECT_EQ(c.weakCount(), 3u);
  EXPECT_NO_THROW(parseOpenCvCascade(replaced(tree, "1 -1 1 1. 0 -2 0 2.5", "1 -1 1 1. 0 -1 0 2.5"), "t.xml"));
  expectError(replaced(tree, "1 -1 1 1. 0 -2 0 2.5", "1 -1 1 1. 1 -2 0 2.5"), "must be a later node or a leaf");
  expectError(replaced(tree, "1 -1 1 1. 0 -2 0 2.5", "1 -1 1 1. 0 -7 0 2.5"), "must be a later node or a leaf");
}

TEST(OpenCvCascade, NonFiniteNumbersAreReported) {
  expectError(replaced(kSmall, "<stageThreshold>-1.5</stageThreshold>", "<stageThreshold>nan</stageThreshold>"),
              "non-finite");
  expectError(replaced(kSmall, "0 -1 0 0.25", "0 -1 0 NaN"), "non-finite");
  expectError(replaced(kSmall, "<leafValues>-1. 1.</leafValues>", "<leafValues>-1. inf</leafValues>"), "non-finite");
  expectError(replaced(kSmall, "0 -1 0 0.25", "0 -1 0 0.2x5"), "expected numbers");
}

TEST(OpenCvCascade, UnknownFeatureOrStageTypesAreReported) {
  expectError(replaced(kSmall, "<featureType>HAAR</featureType>", "<featureType>LBP</featureType>"),
              "feature type 'LBP' is not supported");
  expectError(replaced(kSmall, "<featureType>HAAR</featureType>", "<featureType>WAVELET</featureType>"),
              "feature type 'WAVELET'");
  expectError(replaced(kSmall, "<stageType>BOOST</stageType>", "<stageType>SVM</stageType>"), "stage type 'SVM'");
  expectError(replaced(kSmall, "<tilted>0</tilted>", "<tilted>2</tilted>"), "<tilted> must be 0 or 1");
  expectError(replaced(kSmall, "<opencv_storage>", "<storage>"), "</opencv_storage> closes <storage>");
}

TEST(OpenCvCascade, FuzzedFilesNeverCrash) {
  std::mt19937 rng(20261122);
  const std::string alphabet = "<>/_ -.0123456789eE\n\"=abcdnatfi";
  int parsed = 0, rejected = 0;
  for (int it = 0; it < 3000; ++it) {
    std::string s = kSmall;
    const int edits = 1 + int(rng() % 6);
    for (int e = 0; e < edits && !s.empty(); ++e) {
      const std::size_t at = rng() % s.size();
      switch (rng() % 5) {
        case 0: s[at] = alphabet[rng() % alphabet.size()]; break;                   // replace
        case 1: s.erase(at, 1 + rng() % 20); break;                                 // delete
        case 2: s.insert(at, 1, alphabet[rng() % alphabet.size()]); break;          // insert
        case 3: s.resize(at); break;                                                // truncate
        default: s.insert(at, s.substr(rng() % s.size(), rng() % 40)); break;       // duplicate
      }
    }
    try {
      const Cascade c = parseOpenCvCascade(s, "fuzz.xml");
      c.validate();  // whatever parses is a valid model
      ++parsed;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("fuzz.xml: ", 0), 0u) << e.what();
      ++rejected;
    }
  }
  for (int it = 0; it < 300; ++it) {  // pure garbage, including deep nesting
    std::string s(rng() % 400, '\0');
    for (char& ch : s) ch = static_cast<char>(rng() % 256);
    if (it % 10 == 0) s = std::string(5000, '<') + "a>";
    if (it % 10 == 1) s = "<opencv_storage>" + std::string(200, 'x') + std::string(3000, '<') ;
    EXPECT_THROW(parseOpenCvCascade(s, "garbage.xml"), std::runtime_error);
  }
  EXPECT_GT(rejected, 1000);
  std::printf("fuzz: %d mutated files parsed, %d rejected with a message\n", parsed, rejected);
}
