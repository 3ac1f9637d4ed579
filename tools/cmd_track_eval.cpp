// SPDX-License-Identifier: Apache-2.0
// fusedet track-eval: the tracks of a replayed synthesised KITTI log (`fusedet replay` output)
// against the drive's KITTI tracking labels - CLEAR MOT, HOTA and detection F of raw detections
// against confirmed tracks, per class; optionally the tracks-over-time picture. The rules are
// daemon/tracking (kitti_tracking_eval.h, timeline_plot.h); this file parses and prints.

#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "command.h"
#include "fusedet/drivers/log/channels.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/fusion/datasets/kitti.h"
#include "fusedet/fusion/datasets/kitti_tracks.h"
#include "fusedet/tracking/kitti_tracking_eval.h"
#include "fusedet/tracking/timeline_plot.h"

namespace fusedet::tools {
namespace {

struct TrackEvalOptions {
  std::string detections, log, kitti, png, caption;
  std::vector<std::string> classes{"car", "bike", "person"};
  bool json = false;
};

// The log's synthesised strokes: KITTI frame id and start stamp of each.
void readStrokes(const std::string& log, std::vector<std::string>& ids, std::vector<std::int64_t>& starts) {
  const drivers::logs::LogSource source(log);
  const auto* rec = source.index().findMetadata(drivers::logs::kRecordingMetadata);
  if (!rec || !rec->entries.count("frames") || !rec->entries.count("stroke_starts_ns"))
    throw std::runtime_error(log + ": no fusedet.recording frames / stroke_starts_ns (not made by fusedet synth-log)");
  std::istringstream f(rec->entries.at("frames")), s(rec->entries.at("stroke_starts_ns"));
  for (std::string id; f >> id;) ids.push_back(id);
  for (std::int64_t t; s >> t;) starts.push_back(t);
  if (ids.size() != starts.size() || ids.empty())
    throw std::runtime_error(log + ": fusedet.recording frames and stroke_starts_ns differ in length");
}

std::string measure(const std::optional<double>& v) { return boosting::formatMeasure(v, 3); }

int runTrackEval(const TrackEvalOptions& o) {
  std::vector<std::string> ids;
  std::vector<std::int64_t> starts;
  readStrokes(o.log, ids, starts);
  const fusion::KittiTracks tracks = fusion::readKittiTracks(o.kitti);
  if (tracks.frames.empty()) throw std::runtime_error(o.kitti + ": no tracking_label_02_*.txt");
  std::vector<tracking::TrackedFrame> frames(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) {
    frames[k].labels = fusion::readKittiLabels(std::filesystem::path(o.kitti) / "label_2" / (ids[k] + ".txt"));
    for (const Label& l : frames[k].labels) frames[k].labelTracks.push_back(tracks.trackOf(std::stoi(ids[k]), l));
  }
  std::ifstream in(o.detections);
  if (!in) throw std::runtime_error(o.detections + ": cannot open");
  std::vector<char> seen(ids.size(), 0);
  std::size_t lineNo = 0, stacks = 0;
  for (std::string line; std::getline(in, line);) {
    ++lineNo;
    const auto m = nlohmann::json::parse(line, nullptr, false);
    if (!m.is_object() || m.value("type", "") != "detections")
      throw std::runtime_error(o.detections + ":" + std::to_string(lineNo) + ": not a detections line");
    const int k = tracking::strokeOfSweep(starts, m.at("sweep_start_ns").get<std::int64_t>(), m.at("sweep_end_ns").get<std::int64_t>());
    if (k < 0 || seen[static_cast<std::size_t>(k)]) {
      std::fprintf(stderr, "%s:%zu: stack %s is %s; skipped\n", o.detections.c_str(), lineNo, m.at("stack").dump().c_str(),
                   k < 0 ? "before the first stroke" : "a second stack of one stroke");
      continue;
    }
    seen[static_cast<std::size_t>(k)] = 1;
    ++stacks;
    for (const auto& d : m.at("detections")) {
      tracking::TrackedDetection t;
      t.className = d.at("class").get<std::string>();
      const auto& b = d.at("box");
      t.box = Box{b.at(0).get<double>(), b.at(1).get<double>(), b.at(2).get<double>(), b.at(3).get<double>()};
      t.score = d.value("score", 0.0);
      if (d.value("track", nlohmann::json()).is_number()) t.track = d["track"].get<std::uint64_t>();
      t.confirmed = d.value("confirmed", false);
      frames[static_cast<std::size_t>(k)].detections.push_back(std::move(t));
    }
  }
  nlohmann::json out = nlohmann::json::array();
  std::vector<tracking::TimelinePanel> panels;
  if (!o.json)
    std::printf("%zu KITTI frames, %zu with a stack\n\n| class | objects | trajectories | MOTA | MOTP | ID sw. | frag. | MT/PT/ML | HOTA | DetA | AssA | LocA | raw R/P/F | confirmed R/P/F |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
                ids.size(), stacks);
  for (const std::string& cls : o.classes) {
    const tracking::ClassTracking r = tracking::evaluateTracking(frames, cls);
    const tracking::ClearMot& c = r.clear;
    const std::optional<double> mota = c.truth ? std::optional<double>(c.mota()) : std::nullopt;
    if (o.json) {
      out.push_back({{"class", cls}, {"frames", r.frames}, {"objects", c.truth}, {"trajectories", c.trajectories},
                     {"mota", mota ? nlohmann::json(*mota) : nlohmann::json()}, {"motp", c.motp()},
                     {"matches", c.matches}, {"misses", c.misses}, {"false_positives", c.falsePositives},
                     {"id_switches", c.idSwitches}, {"fragmentations", c.fragmentations},
                     {"mostly_tracked", c.mostlyTracked}, {"partially_tracked", c.partiallyTracked}, {"mostly_lost", c.mostlyLost},
                     {"hota", r.hota.meanHota()}, {"deta", r.hota.meanDetA()}, {"assa", r.hota.meanAssA()}, {"loca", r.hota.meanLocA()},
                     {"raw", {{"hits", r.raw.hits}, {"false_alarms", r.raw.falseAlarms}, {"misses", r.raw.misses}}},
                     {"confirmed", {{"hits", r.confirmed.hits}, {"false_alarms", r.confirmed.falseAlarms}, {"misses", r.confirmed.misses}}}});
    } else {
      std::printf("| %s | %zu | %zu | %s | %.3f | %zu | %zu | %zu/%zu/%zu | %.3f | %.3f | %.3f | %.3f | %s/%s/%s | %s/%s/%s |\n", cls.c_str(),
                  c.truth, c.trajectories, measure(mota).c_str(), c.motp(), c.idSwitches, c.fragmentations, c.mostlyTracked,
                  c.partiallyTracked, c.mostlyLost, r.hota.meanHota(), r.hota.meanDetA(), r.hota.meanAssA(), r.hota.meanLocA(),
                  measure(r.raw.recall()).c_str(), measure(r.raw.precision()).c_str(), measure(r.raw.fMeasure()).c_str(),
                  measure(r.confirmed.recall()).c_str(), measure(r.confirmed.precision()).c_str(),
                  measure(r.confirmed.fMeasure()).c_str());
    }
    if (c.trajectories > 0) {
      char title[200];
      std::snprintf(title, sizeof title, "%s: %zu objects in %zu frames, MOTA %s, %zu id switches, %zu fragmentations, HOTA %.2f",
                    cls.c_str(), c.trajectories, r.frames, measure(mota).c_str(), c.idSwitches, c.fragmentations, r.hota.meanHota());
      panels.push_back({title, r.timeline});
    }
  }
  if (o.json) std::printf("%s\n", out.dump(2).c_str());
  if (!o.png.empty()) {
    const cv::Mat img = tracking::drawTimeline(panels, o.caption.empty() ? o.log : o.caption);
    if (!cv::imwrite(o.png, img)) throw std::runtime_error(o.png + ": cannot write PNG");
  }
  return 0;
}

const bool registered = registerCommand(
    "track-eval", "Score the tracks of a replayed synthesised KITTI log: CLEAR MOT, HOTA, F raw vs confirmed", [](CLI::App& app) {
      auto o = std::make_shared<TrackEvalOptions>();
      app.add_option("detections", o->detections, "NDJSON detections lines (fusedet replay --out)")->required()->check(CLI::ExistingFile);
      app.add_option("--log", o->log, "the synthesised log that was replayed (maps stacks to KITTI frames)")
          ->required()->check(CLI::ExistingFile);
      app.add_option("--kitti", o->kitti, "the KITTI directory the log was made from (label_2/, tracking_label_02_*.txt)")
          ->required()->check(CLI::ExistingDirectory);
      app.add_option("--class", o->classes, "classes to score (repeat)")->capture_default_str();
      app.add_option("--png", o->png, "write the tracks-over-time picture (one panel per class with objects)");
      app.add_option("--caption", o->caption, "the picture's caption (default: the log's path)");
      app.add_flag("--json", o->json, "print JSON instead of the markdown table");
      app.footer(
          "Each stack is the KITTI frame whose synthesised stroke holds its sweep's middle. Per class:\n"
          "labels and ignored detections by fusedet/boost/class_rules.h (KITTI moderate, Van ignored for car,\n"
          "DontCare absorbs) at IoU 0.5; hypotheses = detections of confirmed tracks, ids = track ids;\n"
          "CLEAR MOT (MOTA, MOTP, id switches, fragmentations, mostly tracked/partially/lost), HOTA\n"
          "(DetA, AssA, LocA), and recall/precision/F of every detection (raw) against confirmed ones.\n\n"
          "Example:\n"
          "  fusedet synth-log --kitti ../shared/data/kitti --first 0 --frames 52 --out build/logs/0005.mcap\n"
          "  fusedet replay build/logs/0005.mcap --config config/demo.yaml --out build/0005.ndjson\n"
          "  fusedet track-eval build/0005.ndjson --log build/logs/0005.mcap --kitti ../shared/data/kitti --png tracks.png");
      return [o] { return runTrackEval(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
