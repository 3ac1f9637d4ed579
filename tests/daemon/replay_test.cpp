// SPDX-License-Identifier: Apache-2.0
// The daemon replaying a sensor log (synthesised from KITTI frames of the last third of drive 0005; procedural without
// KITTI data) through its real pipeline - live decoders, sweep assembly, pairing, fusion, the
// bundled cascades, the socket server: deterministic as-fast-as-possible replays, 50 mixed
// clients at once with nothing lost for those that keep up, damaged logs.

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <map>
#include <thread>

#include "../process_temp_dir.h"
#include "fusedet/daemon/client.h"
#include "fusedet/daemon/offline_replay.h"
#include "fusedet/daemon/protocol.h"
#include "fusedet/daemon/replay_source.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/daemon/service.h"
#include "fusedet/daemon/service_parts.h"
#include "fusedet/drivers/log/mcap_reader.h"
#include "fusedet/drivers/log/recorder.h"
#include "fusedet/drivers/log/replay.h"
#include "replay_logs.h"

using namespace fusedet;
using namespace fusedet::daemon;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

constexpr int kStrokes = 3;  // strokes in the test log = stacks per pass

std::string tempSocket(const std::string& name) {
  return (test::processTempDir() / name).string();
}

std::string model(const std::string& cls) { return std::string(FUSEDET_SOURCE_DIR) + "/models/" + cls + ".json"; }

Config replayConfig(const std::string& socket, const fs::path& log) {
  Config c;
  c.socket.path = socket;
  c.detection.models = {model("car"), model("bike"), model("person")};
  c.replay.file = log.string();
  c.replay.realtime = false;
  c.replay.restamp = false;
  c.replay.atEnd = "idle";
  return c;
}

std::unique_ptr<Service> startReplay(const Config& config) {
  ServiceParts parts = replayParts(config, {});
  parts.listener = bindUnixSocket(config.socket.path);
  auto service = std::make_unique<Service>(std::move(parts));
  return service;
}

// A detections line without what depends on the machine's speed (timings, detection time).
nlohmann::json content(nlohmann::json line) {
  line.erase("fuse_ms");
  line.erase("detect_ms");
  line.erase("stages_ms");
  line.erase("detected_ns");
  return line;
}

// Subscribes (before the service starts, so nothing is missed), reads every detections line
// until the replay finished and the queue is drained.
// With `tracks`, the client also subscribes to the tracks stream and collects its lines there.
std::vector<nlohmann::json> replayOnce(const Config& config, nlohmann::json* status = nullptr,
                                       std::vector<nlohmann::json>* tracks = nullptr) {
  auto service = startReplay(config);
  Client client(config.socket.path);
  client.send({{"cmd", "subscribe"}});
  if (tracks) client.send({{"cmd", "subscribe"}, {"stream", "tracks"}});
  service->start();
  std::vector<nlohmann::json> lines;
  auto take = [&](const nlohmann::json& m) {
    if (m["type"] == "detections") lines.push_back(content(m));
    if (tracks && m["type"] == "tracks") tracks->push_back(m);
  };
  const auto end = std::chrono::steady_clock::now() + 300s;
  while (std::chrono::steady_clock::now() < end) {
    auto m = client.read(200ms);
    if (m) take(*m);
    if (!m && service->finished()) break;
  }
  while (auto m = client.read(500ms)) take(*m);
  if (status) *status = service->status();
  service->stop(std::chrono::steady_clock::now() + 1500ms);
  return lines;
}

}  // namespace

TEST(ReplayService, AsFastAsPossibleEveryStrokeIsDetectedAndTwoRunsAgree) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  const Config config = replayConfig(tempSocket("fast.sock"), log);
  nlohmann::json status;
  const auto first = replayOnce(config, &status);
  const auto second = replayOnce(config);

  // One stack per stroke of the nodding unit, none dropped although detection is far slower
  // than reading the log.
  ASSERT_EQ(first.size(), static_cast<std::size_t>(kStrokes)) << status.dump();
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_EQ(first[i]["stack"], i);
  EXPECT_EQ(status["mode"], "replay");
  EXPECT_EQ(status["pipeline"]["stack_queue"]["dropped"], 0);
  EXPECT_EQ(status["pipeline"]["sensor_queue"]["dropped"], 0);
  EXPECT_EQ(status["pipeline"]["unpaired_sweeps"], 0);
  EXPECT_EQ(status["pipeline"]["decode_errors"], 0);
  const auto& replay = status["sensors"][0];
  EXPECT_EQ(replay["name"], "replay");
  EXPECT_EQ(replay["state"], "finished");
  EXPECT_EQ(replay["progress"], 1.0);
  EXPECT_EQ(replay["passes"], 1);
  EXPECT_EQ(replay["crc_errors"], 0);
  EXPECT_EQ(replay["last_error"], "");
  // Deterministic: the same stacks, stamps, boxes, scores and positions.
  EXPECT_EQ(first, second);

  // Recorded stamps (restamp off): every sweep and frame lies inside the log's time span.
  const drivers::mcap::McapReader reader(log);
  const auto logStart = static_cast<std::int64_t>(reader.index().start);
  const auto logEnd = static_cast<std::int64_t>(reader.index().end);
  std::size_t found = 0;
  for (const auto& line : first) {
    EXPECT_GE(line["sweep_start_ns"].get<std::int64_t>(), logStart);
    EXPECT_LT(line["sweep_start_ns"].get<std::int64_t>(), line["sweep_end_ns"].get<std::int64_t>());
    EXPECT_LE(line["sweep_end_ns"].get<std::int64_t>(), logEnd);
    EXPECT_GE(line["frame_ns"].get<std::int64_t>(), logStart);
    EXPECT_LE(line["frame_ns"].get<std::int64_t>(), logEnd);
    for (const auto& d : line["detections"]) {
      ++found;
      EXPECT_EQ(d["box"].size(), 4u);
      if (d["camera"].is_null()) continue;
      const double range = d["range"];
      const double camNorm = std::hypot(d["camera"][0].get<double>(), d["camera"][1].get<double>(), d["camera"][2].get<double>());
      EXPECT_NEAR(camNorm, range, 1e-6 + 1e-3 * range);  // range = distance from the camera centre
      EXPECT_GT(d["camera"][2].get<double>(), 0.0) << "in front of the camera";
    }
  }
  // The bundled models find something in those KITTI frames (training frames of theirs) (the demo relies on it).
  if (testlogs::haveKitti()) {
    EXPECT_GT(found, 0u);
  }
}

TEST(ReplayService, FiftyMixedClientsOnAReplayingDaemonKeepersLoseNothing) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  Config config = replayConfig(tempSocket("mixed.sock"), log);
  config.replay.atEnd = "loop";  // several passes: a steady stream of stacks
  config.replay.restamp = true;
  config.socket.maxClients = 64;
  config.socket.clientQueue = 16;
  config.socket.maxRequestBytes = 1024;
  auto service = startReplay(config);
  const std::string path = config.socket.path;
  constexpr std::uint64_t kLast = 3 * kStrokes - 1;  // keepers read until this stack

  struct Got {
    std::vector<nlohmann::json> lines;
    std::vector<nlohmann::json> stages;  // stages_ms of each line
    bool closed = false;
  };
  auto follow = [&](Got& got, std::chrono::milliseconds pause, const std::vector<std::string>& classes) {
    Client c(path);
    nlohmann::json req{{"cmd", "subscribe"}};
    if (!classes.empty()) req["classes"] = classes;
    c.send(req);
    const auto end = std::chrono::steady_clock::now() + 300s;
    while (std::chrono::steady_clock::now() < end) {
      auto m = c.read(1s);
      if (!m) {
        if (c.closed()) {
          got.closed = true;
          return;
        }
        continue;
      }
      if ((*m)["type"] != "detections") continue;
      got.lines.push_back(content(*m));
      got.stages.push_back((*m)["stages_ms"]);
      if ((*m)["stack"].get<std::uint64_t>() >= kLast) return;
      if (pause.count()) std::this_thread::sleep_for(pause);
    }
  };

  Got reference;
  std::vector<Got> normal(19), filtered(5), slow(5);
  std::vector<std::thread> threads;
  threads.emplace_back([&] { follow(reference, 0ms, {}); });
  for (auto& g : normal) threads.emplace_back([&, p = &g] { follow(*p, 0ms, {}); });
  for (auto& g : filtered) threads.emplace_back([&, p = &g] { follow(*p, 0ms, {"bike"}); });
  for (auto& g : slow) threads.emplace_back([&, p = &g] { follow(*p, 400ms, {}); });
  // Silent: subscribe, ask for lots (once the server runs) and never read: dropped once their
  // queue overflows.
  std::vector<std::unique_ptr<Client>> silent;
  for (int i = 0; i < 5; ++i) {
    silent.push_back(std::make_unique<Client>(path));
    silent.back()->send({{"cmd", "subscribe"}});
  }
  std::atomic<int> malformedOk{0}, oversizedOk{0}, flaps{0};
  for (int i = 0; i < 6; ++i)
    threads.emplace_back([&, i] {
      Client c(path);
      if (i % 2) {
        c.sendLine("{\"cmd\": \"subscribe\", \"classes\": [tru");
        c.sendLine("\x01\x02\xff garbage");
        auto e1 = c.read(30s), e2 = c.read(30s);
        if (e1 && e2 && (*e1)["type"] == "error" && (*e2)["type"] == "error") {
          c.send({{"cmd", "hello"}});
          auto h = c.read(30s);
          if (h && (*h)["type"] == "hello" && (*h)["mode"] == "replay") ++malformedOk;
        }
      } else {
        c.sendLine(std::string(100000, 'x'));
        auto e = c.read(30s);
        if (e && (*e)["type"] == "error" && (*e)["error"].get<std::string>().find("longer than 1024") != std::string::npos) {
          c.send({{"cmd", "status"}});
          auto s = c.read(30s);
          if (s && (*s)["type"] == "status") ++oversizedOk;
        }
      }
    });
  std::atomic<bool> flapping{true};
  for (int i = 0; i < 9; ++i)
    threads.emplace_back([&, i] {
      while (flapping) {
        try {
          Client c(path);
          c.send({{"cmd", "subscribe"}});
          if (i % 2) (void)c.read(50ms);
          ++flaps;
          std::this_thread::sleep_for(10ms);
        } catch (const std::exception&) {
          // refused at the client limit: try again
        }
      }
    });
  std::this_thread::sleep_for(300ms);  // most clients are connected before the first stack
  service->start();
  for (auto& c : silent)
    threads.emplace_back([c = c.get()] {
      try {
        for (int k = 0; k < 1000; ++k) c->send({{"cmd", "status"}});
      } catch (const std::system_error&) {
        // dropped while still asking: what should happen
      }
    });
  const std::size_t followers = 1 + normal.size() + filtered.size() + slow.size();
  for (std::size_t i = 0; i < followers; ++i) threads[i].join();
  flapping = false;
  for (std::size_t i = followers; i < threads.size(); ++i) threads[i].join();

  // The reference saw the stacks in order without a gap; as fast as possible nothing is dropped.
  ASSERT_FALSE(reference.lines.empty());
  ASSERT_EQ(reference.lines.back()["stack"], kLast);
  std::map<std::uint64_t, nlohmann::json> all;
  for (const auto& l : reference.lines) all[l["stack"].get<std::uint64_t>()] = l;
  const std::uint64_t firstSeen = reference.lines.front()["stack"];
  EXPECT_EQ(all.size(), kLast - firstSeen + 1);
  // Each line says where its time went: every stage present, the measured durations not
  // negative (`close` compares stamps with the clock: replayed faster than recorded, the stamps
  // run ahead of it).
  for (const auto& st : reference.stages) {
    ASSERT_TRUE(st.contains("close") && st["close"].is_number()) << st.dump();
    for (const char* key : {"decode", "fuse", "neural", "fuse_cpu", "queue", "detect", "detect_cpu", "localize"}) {
      ASSERT_TRUE(st.contains(key)) << key << " missing in " << st.dump();
      EXPECT_GE(st[key].get<double>(), 0.0) << key;
    }
  }
  // Every client that keeps up got every stack from its first on, identical to the reference.
  auto check = [&](const Got& g, bool bikesOnly) {
    ASSERT_FALSE(g.closed);
    ASSERT_FALSE(g.lines.empty());
    std::uint64_t expect = g.lines.front()["stack"];
    EXPECT_LE(expect, kStrokes - 1u) << "subscribed before the first pass ended";
    for (const auto& l : g.lines) {
      ASSERT_EQ(l["stack"], expect++);
      nlohmann::json ref = all.count(l["stack"]) ? all[l["stack"]] : nlohmann::json();
      if (ref.is_null()) continue;  // before the reference's first stack
      if (bikesOnly) {
        nlohmann::json bikes = nlohmann::json::array();
        for (const auto& d : ref["detections"])
          if (d["class"] == "bike") bikes.push_back(d);
        ref["detections"] = bikes;
      }
      EXPECT_EQ(l, ref);
    }
    EXPECT_EQ(expect, kLast + 1);
  };
  for (const auto& g : normal) check(g, false);
  for (const auto& g : filtered) check(g, true);
  // Slow clients: in order and without a gap for as long as they stayed.
  for (const auto& g : slow)
    for (std::size_t i = 1; i < g.lines.size(); ++i) EXPECT_EQ(g.lines[i]["stack"], g.lines[i - 1]["stack"].get<std::uint64_t>() + 1);
  EXPECT_EQ(malformedOk, 3);
  EXPECT_EQ(oversizedOk, 3);
  EXPECT_GT(flaps, 9);
  const auto status = service->status();
  EXPECT_GE(status["clients"]["dropped_slow"].get<int>(), 5) << status.dump();
  EXPECT_EQ(status["clients"]["bad_requests"], 6);
  EXPECT_EQ(status["clients"]["oversized_requests"], 3);
  EXPECT_EQ(status["pipeline"]["stack_queue"]["dropped"], 0);
  EXPECT_GE(status["sensors"][0]["passes"].get<int>(), 2);
  // Looping faster than recorded: each pass is stamped after the last, so every stroke of every
  // pass is a whole sweep paired with its frame (a pass restamped to "now" went back in time:
  // sweeps cut at the seam, frames unpaired, scans without tilt).
  EXPECT_EQ(status["pipeline"]["unpaired_sweeps"], 0) << status.dump();
  EXPECT_EQ(status["pipeline"]["scans_dropped_no_tilt"], 0) << status.dump();
  // The replay counts a pass when it reaches the log's end; fusion may still be on that pass's
  // last messages (up to half the 512-message sensor queue, less than a pass) when status is read.
  EXPECT_GE(status["pipeline"]["stacks_fused"].get<int>(), kStrokes * (status["sensors"][0]["passes"].get<int>() - 1));
  // Stamps ahead of the clock are no latency: none is reported (it was negative).
  EXPECT_EQ(status["latency_ms"]["samples"], 0) << status.dump();
  for (auto& s : silent) {
    while (s->readLine(5s)) {
    }
    EXPECT_TRUE(s->closed()) << "a silent client was not dropped";
  }
  const auto t0 = std::chrono::steady_clock::now();
  service->stop(t0 + 1500ms);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
}

// The log's rig replaces the fusion section, but how sweeps close is this machine's choice.
TEST(ReplayService, CloseOnTiltComesFromTheMachineConfigNotTheLog) {
  const std::filesystem::path log = testlogs::daemonTestLog(1);
  for (const bool onTilt : {true, false}) {
    Config machine;
    machine.fusion.closeOnTilt = onTilt;
    machine.fusion.tiltWindowMs = 7;  // a rig value: the log's (default 50) wins
    const ReplayRig rig = replayRig(log, machine, {});
    EXPECT_EQ(rig.config.fusion.closeOnTilt, onTilt);
    EXPECT_EQ(sweepConfig(rig.config).closeOnTilt, onTilt);
    EXPECT_EQ(rig.config.fusion.tiltWindowMs, 50);
  }
}

TEST(ReplayService, ACutLogReplaysWhatIsIntactAndGarbageIsAClearError) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  const fs::path dir = fs::path(tempSocket("x")).parent_path();
  const fs::path cut = dir / "cut.mcap";
  fs::copy_file(log, cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(log) * 3 / 4);
  nlohmann::json status;
  const auto lines = replayOnce(replayConfig(tempSocket("cut.sock"), cut), &status);
  const auto& replay = status["sensors"][0];
  EXPECT_EQ(replay["state"], "finished");
  EXPECT_NE(replay["last_error"].get<std::string>().find("cut"), std::string::npos) << replay.dump();
  // Three quarters of three strokes: at least the first complete stroke is fused and detected.
  EXPECT_GE(lines.size(), 1u);
  EXPECT_LE(lines.size(), static_cast<std::size_t>(kStrokes));

  for (const std::string& garbage : {std::string(), std::string("not a log at all\n"), std::string(5000, '\x89')}) {
    const fs::path bad = dir / "bad.mcap";
    std::ofstream(bad, std::ios::binary) << garbage;
    try {
      (void)replayParts(replayConfig(tempSocket("bad.sock"), bad), {});
      ADD_FAILURE() << "accepted a log of " << garbage.size() << " bytes of garbage";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
  }
  try {
    (void)replayParts(replayConfig(tempSocket("none.sock"), dir / "missing.mcap"), {});
    ADD_FAILURE() << "accepted a missing log";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.mcap"), std::string::npos) << e.what();
  }
}

// Line noise on the laser's serial link, as recorded: one byte in every 40th serial chunk of the
// test log inverted (an independent edit of the raw bytes, not the telegram encoder). The daemon's
// status counts the CRC errors under the replay sensor, and the replay still fuses and detects.
TEST(ReplayService, LaserLineNoiseShowsAsCrcErrorsInStatusAndTheReplayGoesOn) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  const fs::path noisy = fs::path(tempSocket("x")).parent_path() / "noisy.mcap";
  std::size_t chunks = 0, flipped = 0;
  {
    drivers::logs::LogSource in(log);
    drivers::logs::Recorder out(noisy);
    const auto rig = in.rig();
    ASSERT_TRUE(rig);
    out.setRig(rig->configYaml, rig->cameraYaml);
    drivers::logs::LogSource::Handlers h;
    h.serial = [&](const drivers::logs::SerialChunk& c) {
      drivers::logs::SerialChunk copy = c;
      if (++chunks % 40 == 0 && copy.bytes.size() > 8) {
        copy.bytes[copy.bytes.size() / 2] ^= 0xff;
        ++flipped;
      }
      out.record(copy);
    };
    h.can = [&](const drivers::logs::CanMessage& m) { out.record(m); };
    h.camera = [&](const drivers::CameraFrame& f) { out.record(f); };
    while (in.step(h)) {
    }
    out.close();
  }
  ASSERT_GT(flipped, 5u);
  nlohmann::json status;
  const auto lines = replayOnce(replayConfig(tempSocket("noisy.sock"), noisy), &status);
  const auto& replay = status["sensors"][0];
  std::printf("%zu of %zu serial chunks with an inverted byte: crc_errors %s, lost %s, %zu stacks\n", flipped, chunks,
              replay["crc_errors"].dump().c_str(), replay["lost"].dump().c_str(), lines.size());
  // CRC-16 catches every inverted byte inside a telegram (one that hits a header byte may instead
  // hide the telegram from the reader; resynchronising inside a damaged one can add more).
  EXPECT_GE(replay["crc_errors"].get<std::uint64_t>(), flipped / 2) << replay.dump();
  EXPECT_EQ(replay["state"], "finished");
  EXPECT_GE(lines.size(), 1u) << status.dump();
}

// Issue 37: an exception from the MCAP reader (here: the log shrank after it was indexed, as when
// it is replaced or cut while the daemon replays it) escaped the replay thread and ended the
// process through std::terminate. Now the replay ends as a failed source whose last_error says
// why; the service keeps serving.
TEST(ReplayService, ALogThatShrinksUnderTheReplayFailsTheSourceNotTheProcess) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  const fs::path shrinking = fs::path(tempSocket("x")).parent_path() / "shrinking.mcap";
  fs::copy_file(log, shrinking, fs::copy_options::overwrite_existing);
  const Config config = replayConfig(tempSocket("shrink.sock"), shrinking);
  auto service = startReplay(config);  // the log is indexed here, whole
  fs::resize_file(shrinking, fs::file_size(log) / 3);
  service->start();
  const auto end = std::chrono::steady_clock::now() + 120s;
  while (!service->finished() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(50ms);
  ASSERT_TRUE(service->finished());
  EXPECT_TRUE(service->failed());
  const nlohmann::json status = service->status();
  const auto& replay = status["sensors"][0];
  EXPECT_EQ(replay["state"], "failed") << replay.dump();
  EXPECT_NE(replay["last_error"].get<std::string>().find("shrank"), std::string::npos) << replay.dump();
  Client client(config.socket.path);  // still serving
  client.send({{"cmd", "hello"}});
  auto hello = client.read(5s);
  ASSERT_TRUE(hello);
  EXPECT_EQ((*hello)["type"], "hello");
  service->stop(std::chrono::steady_clock::now() + 1500ms);
}

// `fusedet replay`'s runner gives exactly the socket's detections lines (timings aside), with
// track ids that the tracks stream of the same stack lists with the same class and state.
TEST(ReplayService, OfflineReplayWritesTheSocketsLinesAndTracksAgree) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  const Config config = replayConfig(tempSocket("offline.sock"), log);
  std::vector<nlohmann::json> tracks;
  const auto socket = replayOnce(config, nullptr, &tracks);
  std::vector<nlohmann::json> offline;
  const OfflineReplayReport report =
      replayOffline(config, {}, log, [&](const StackResult& r) { offline.push_back(content(resultToJson(r))); });
  EXPECT_EQ(report.counters.stacksDetected, static_cast<std::uint64_t>(kStrokes));
  EXPECT_EQ(report.damage, "");
  ASSERT_EQ(offline.size(), static_cast<std::size_t>(kStrokes));
  EXPECT_EQ(offline, socket);

  ASSERT_EQ(tracks.size(), socket.size());
  std::size_t tracked = 0;
  for (std::size_t k = 0; k < socket.size(); ++k) {
    EXPECT_EQ(tracks[k]["stack"], socket[k]["stack"]);
    std::map<std::uint64_t, nlohmann::json> live;
    for (const auto& t : tracks[k]["tracks"]) live[t["id"].get<std::uint64_t>()] = t;
    for (const auto& d : socket[k]["detections"]) {
      if (d["robot"].is_null()) {
        EXPECT_TRUE(d["track"].is_null()) << "no position, no track";
        continue;
      }
      ++tracked;
      ASSERT_TRUE(d["track"].is_number()) << d.dump();
      const auto it = live.find(d["track"].get<std::uint64_t>());
      ASSERT_NE(it, live.end()) << "track of a detection missing from the tracks line";
      EXPECT_EQ(it->second["class"], d["class"]);
      EXPECT_EQ(it->second["confirmed"], d["confirmed"]);
      EXPECT_EQ(it->second["coasting"], false);
      EXPECT_EQ(it->second["velocity"], d["velocity"]);
    }
  }
  EXPECT_GT(tracked, 0u) << "the test log's detections have laser positions";
}
