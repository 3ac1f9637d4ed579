// SPDX-License-Identifier: Apache-2.0
// The bundled models' decisions, pinned: every model of models/ run as fusedetd runs it - the
// shipped config/fusedet.yaml's detection section (scan, grouping, per-class settings: car with its
// own neighbours and laser extent) through daemon::CascadeSet, then each detection's 3D position
// from daemon::localize() as the pipeline computes it - on KITTI frames fused as the other KITTI
// tests fuse them (fusion::readKittiFrame + kittiFuser). Every detection (class, box, score,
// position) and, per model, the raw hits of the scan (count, score sum, each hit's box and score)
// and the windows / stumps evaluated must equal tests/daemon/data/detection_decisions.txt.
//
// The expected file was written from main at 60b042f (before issue 29's deletions) and is there
// to prove that deleting options, splitting folders and renaming leave the daemon's decisions
// alone. Do not regenerate it to make this test pass: a difference means a change altered what a
// robot detects. Regenerate only for a deliberate change of decisions (new bundled models, a new
// default), say so in the commit message, and quote the old and new counts there:
//   FUSEDET_WRITE_DECISIONS=1 ctest --test-dir build -R DetectionDecisions
// (writes the file in the source tree; review `git diff tests/daemon/data/detection_decisions.txt`).
// Without the shared KITTI data the test skips, as the other KITTI tests do.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "fusedet/boost/model_io.h"
#include "fusedet/boost/multi_detector.h"
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/localize.h"
#include "fusedet/daemon/stack_detector.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::daemon {
namespace {
namespace fs = std::filesystem;

const fs::path kData = FUSEDET_DATA_DIR;
const fs::path kSource = FUSEDET_SOURCE_DIR;
const fs::path kExpected = kSource / "tests" / "daemon" / "data" / "detection_decisions.txt";

// A frame of drive 0005 with detections of all three classes, one where car's own settings change
// car's detections (tests/tools/class_detection_commands_test.cpp), and one of drive 0009.
struct Frame {
  std::string folder, id;
};
const std::vector<Frame> kFrames = {{"kitti", "000000"}, {"kitti", "000060"}, {"kitti_0009", "000020"}};

// The shipped config's detection section with the checkout's models (the installed paths are
// /usr/share/fusedet/models/*.json, the same files) and one thread (the decisions are the same for
// any thread count, multi_detector.h; one keeps the test's own timing out of it).
Config::Detection shippedDetection() {
  Config::Detection d = loadConfig(kSource / "config" / "fusedet.yaml").detection;
  for (std::string& m : d.models) m = (kSource / "models" / fs::path(m).filename()).string();
  d.threads = 1;
  return d;
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

// One line per fact, whitespace-separated: what the test writes and compares.
std::vector<std::string> decisionsOf(const Frame& frame, const Config::Detection& settings) {
  const fusion::KittiFrame f = fusion::readKittiFrame(kData / frame.folder, frame.id);
  const fusion::Fuser fuser = fusion::kittiFuser(f.calib, f.image.cols, f.image.rows);
  const LayerStack stack = fuser.fuse(f.image, f.points);
  const std::string at = frame.folder + "/" + frame.id;
  std::vector<std::string> lines;

  const CascadeSet daemonDetector(settings);
  const std::vector<Detection> found = daemonDetector.detect(stack);
  for (const Detection& d : found) {
    std::string line = at + " detection " + d.className + " score " + fmt(d.score) + " box " + fmt(d.box.x) + " " +
                       fmt(d.box.y) + " " + fmt(d.box.w) + " " + fmt(d.box.h);
    const auto p = localize(stack, d.box, fuser.projection().K, fuser.projection().sweepToCamera);
    if (p)
      line += " position " + fmt(p->robot.x()) + " " + fmt(p->robot.y()) + " " + fmt(p->robot.z()) + " cells " +
              std::to_string(p->cells);
    else
      line += " position none";
    lines.push_back(line);
  }

  // The raw hits under those detections: the same models, in the same order, the same scan.
  std::vector<boosting::Cascade> cascades;
  for (const fs::path& file : daemonDetector.files()) cascades.push_back(boosting::loadModel(file));
  const boosting::MultiDetector models(std::move(cascades));
  std::vector<boosting::ScanStats> stats;
  const auto hits = models.scan(stack, scanParamsFrom(settings), &stats);
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const std::string model = at + " model " + models.cascade(i).className;
    double sum = 0;
    for (const boosting::RawHit& h : hits[i]) sum += h.score;
    lines.push_back(model + " raw_hits " + std::to_string(hits[i].size()) + " score_sum " + fmt(sum) + " windows " +
                    std::to_string(stats.at(i).windows) + " stumps " + std::to_string(stats.at(i).stumps));
    for (const boosting::RawHit& h : hits[i])
      lines.push_back(model + " hit score " + fmt(h.score) + " box " + fmt(h.box.x) + " " + fmt(h.box.y) + " " +
                      fmt(h.box.w) + " " + fmt(h.box.h));
  }
  return lines;
}

std::vector<std::string> tokens(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

// Words equal; numbers with a '.' equal to 1e-4 (the file's 6 decimals leave room for the last
// digit of a rounding, nothing a decision could hide in); integers exactly.
bool sameLine(const std::string& got, const std::string& want) {
  const std::vector<std::string> a = tokens(got), b = tokens(want);
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] == b[i]) continue;
    if (a[i].find('.') == std::string::npos || b[i].find('.') == std::string::npos) return false;
    char* endA = nullptr;
    char* endB = nullptr;
    const double x = std::strtod(a[i].c_str(), &endA), y = std::strtod(b[i].c_str(), &endB);
    if (*endA != '\0' || *endB != '\0' || std::abs(x - y) > 1e-4) return false;
  }
  return true;
}

bool haveData() {
  for (const Frame& f : kFrames)
    if (!fs::is_regular_file(kData / f.folder / "velodyne" / (f.id + ".bin"))) return false;
  return true;
}

TEST(DetectionDecisions, BundledModelsDecideAsOnMainBeforeIssue29) {
  if (!haveData()) GTEST_SKIP() << "no KITTI data at " << kData;
  const Config::Detection settings = shippedDetection();
  std::vector<std::string> got;
  for (const Frame& f : kFrames)
    for (std::string& line : decisionsOf(f, settings)) got.push_back(std::move(line));

  if (std::getenv("FUSEDET_WRITE_DECISIONS")) {
    std::ofstream out(kExpected);
    out << "# Written by tests/daemon/detection_decisions_test.cpp (FUSEDET_WRITE_DECISIONS=1); read its header before\n"
           "# regenerating. Frames of ../shared/data, models/*.json, config/fusedet.yaml's detection section.\n";
    for (const std::string& line : got) out << line << '\n';
    ASSERT_TRUE(out.good()) << "cannot write " << kExpected;
    GTEST_SKIP() << "wrote " << got.size() << " lines to " << kExpected;
  }

  std::ifstream in(kExpected);
  ASSERT_TRUE(in) << "cannot read " << kExpected;
  std::vector<std::string> want;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') want.push_back(line);

  // The file must hold detections of more than one class, or it guards too little.
  std::map<std::string, int> classes;
  for (const std::string& line : want)
    if (const auto t = tokens(line); t.size() > 2 && t[1] == "detection") ++classes[t[2]];
  EXPECT_GE(classes.size(), 2u) << kExpected << " holds detections of fewer than two classes";

  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::max(got.size(), want.size()); ++i) {
    const std::string g = i < got.size() ? got[i] : "(nothing)";
    const std::string w = i < want.size() ? want[i] : "(nothing)";
    if (sameLine(g, w)) continue;
    if (++differ <= 20) ADD_FAILURE() << "line " << i + 1 << " of the decisions:\n  got:      " << g << "\n  expected: " << w;
  }
  EXPECT_EQ(differ, 0u) << "of " << want.size() << " expected lines (" << got.size() << " computed)";
  EXPECT_EQ(got.size(), want.size());
}

}  // namespace
}  // namespace fusedet::daemon
