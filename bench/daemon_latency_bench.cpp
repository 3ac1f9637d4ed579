// SPDX-License-Identifier: Apache-2.0
// Sensor-stamp-to-socket latency of the whole daemon replaying a sensor log: a log synthesised
// from KITTI frames of the last third of drive 0005 (raw LMS telegrams, CANopen tilt traffic, YUYV camera frames) is
// replayed at recorded speed and re-stamped to "now" (as if the sensors were live) into a running
// Service - live decoders, sweep assembly, pairing, fusion, the car, bike and person cascades, the
// socket server - and a socket client measures (receive time - sensor stamp of the stack). Beside
// it, on the same stacks in the same run: the pipeline's pure compute (fuse + detect), the floor
// any queueing, sweep closing and socket overhead adds to.
// --viewers 0,1,5: after that run, the same replay again once per count with the live view on
// (live.listen on loopback, docs/live-view.md) and that many WebSocket viewers subscribed to
// every channel and reading as fast as they can (live_viewers.h): the latency table with 0, 1 and
// 5 viewers beside the run without the live view.
// --neural darknet,yolov5-onnx: after that, the same replay once per network kind with neural
// layers on (config section neural: Yolo-Fastest-XL or YOLOv5n at 832x256 from --networks, on the
// pipeline's network thread), beside the run without them: latency, the network's time per stack,
// and the stacks its queue dropped (live pacing: a network slower than the sweeps drops the oldest).

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <map>
#include <thread>

#include "fusedet/boost/vector_path.h"
#include "fusedet/core/percentile.h"
#include "fusedet/daemon/client.h"
#include "fusedet/daemon/service.h"
#include "fusedet/daemon/service_parts.h"
#include "fusedet/daemon/stats.h"
#include "fusedet/daemon/thread_info.h"
#include "fusedet/fusion/synthesis/synth_log.h"
#include "live_viewers.h"

using namespace fusedet;
using namespace fusedet::daemon;
namespace fs = std::filesystem;

namespace {

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

// CPU time each thread used since `before` (threads that started later: all of theirs).
std::vector<ThreadCpu> since(const std::vector<ThreadCpu>& before, std::vector<ThreadCpu> now) {
  for (ThreadCpu& t : now)
    for (const ThreadCpu& b : before)
      if (b.tid == t.tid) t.cpuMs -= b.cpuMs;
  return now;
}

struct Run {
  std::vector<double> latency, compute, deliver;
  std::map<std::string, std::vector<double>> stages;  // stages_ms of each detections line
  std::vector<std::string> perStack;
  PipelineCounters counters;
  nlohmann::json status;
  std::vector<ThreadCpu> threadCpu;
  double seconds = 0;
  std::uint64_t viewerMessages = 0, viewerBytes = 0;
  int viewersDropped = 0;
};

// CPU ms of the run's threads called `name`.
double threadCpuOf(const Run& r, const std::string& name) {
  double ms = 0;
  for (const ThreadCpu& t : r.threadCpu)
    if (t.name == name) ms += t.cpuMs;
  return ms;
}

// One service replaying the log `passes` times, a socket client measuring; viewers >= 0: the
// live view on with that many viewers; config.neural as given.
Run replay(Config config, int passes, int viewers) {
  Run run;
  auto& latency = run.latency;
  auto& compute = run.compute;
  auto& deliver = run.deliver;
  auto& stages = run.stages;
  auto& perStack = run.perStack;
  if (viewers >= 0) {
    config.live.listen = "127.0.0.1:0";
    config.socket.path += "." + std::to_string(viewers);
  }
  if (config.neural.enabled) config.socket.path += ".neural-" + config.neural.kind;
  ServiceParts parts = replayParts(config, {});
  parts.listener = bindUnixSocket(config.socket.path);
  Service service(std::move(parts));
  Client client(config.socket.path);
  client.send({{"cmd", "subscribe"}});
  const std::vector<ThreadCpu> threadsAtStart = processThreadCpu();
  service.start();
  std::unique_ptr<fusedet::bench::LiveViewers> live;
  if (viewers > 0) live = std::make_unique<fusedet::bench::LiveViewers>("127.0.0.1", service.liveServer()->address().port, viewers);
  const auto t0 = std::chrono::steady_clock::now();

  std::uint64_t lastStack = UINT64_MAX;  // the last stack of the last pass, once fusion has flushed it
  while (true) {
    auto line = client.readLine(std::chrono::seconds(30));
    if (!line) break;
    const Stamp received = Stamp::now();
    const auto m = nlohmann::json::parse(*line);
    if (m["type"] != "detections") continue;
    latency.push_back(static_cast<double>(received.ns - m["sensor_ns"].get<std::int64_t>()) * 1e-6);
    // The stack's own work on its way: fusion, the network (0 without one), detection.
    compute.push_back(m["fuse_ms"].get<double>() + m["stages_ms"].value("neural", 0.0) + m["detect_ms"].get<double>());
    for (const auto& [stage, ms] : m["stages_ms"].items()) stages[stage].push_back(ms.get<double>());
    deliver.push_back(static_cast<double>(received.ns - m["detected_ns"].get<std::int64_t>()) * 1e-6);
    char row[200];
    std::snprintf(row, sizeof row, "  %5llu %9.1f %7.1f %7.1f %7.1f %7.1f %7.1f %7.1f %7.1f %4zu",
                  static_cast<unsigned long long>(m["stack"].get<std::uint64_t>()), latency.back(),
                  stages["close"].back(), stages["decode"].back() + stages["fuse"].back(), stages["fuse_cpu"].back(),
                  stages["queue"].back(), stages["detect"].back(), stages["detect_cpu"].back(), deliver.back(),
                  m["detections"].size());
    perStack.push_back(row);
    const auto pc = service.pipeline().counters();
    if (lastStack == UINT64_MAX && pc.streamEnds >= static_cast<std::uint64_t>(passes)) lastStack = pc.stacksFused - 1;
    if (m["stack"].get<std::uint64_t>() >= lastStack) break;
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (live) {
    live->stop();
    run.viewerMessages = live->messages();
    run.viewerBytes = live->bytes();
    run.viewersDropped = live->disconnected();
  }
  run.counters = service.pipeline().counters();
  run.status = service.status();
  run.threadCpu = since(threadsAtStart, processThreadCpu());
  service.stop(std::chrono::steady_clock::now() + std::chrono::milliseconds(1500));
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench_daemon_latency - sensor stamp to socket client latency of fusedetd replaying a sensor log"};
  std::string data = FUSEDET_DATA_DIR, models = FUSEDET_SOURCE_DIR "/models", log;
  int frames = 6, passes = 3, threads = 0;
  double speed = 1.0;
  bool closeOnScan = false;
  std::vector<int> viewerCounts;
  std::vector<std::string> neuralKinds;
  std::string networks = FUSEDET_NETWORKS_DIR;
  app.add_option("--data", data, "root of the shared data (the log is made from its kitti/ folder)")->capture_default_str();
  app.add_option("--models", models, "folder with car.json, bike.json, person.json")->capture_default_str();
  app.add_option("--log", log, "replay this sensor log instead of synthesising one");
  app.add_option("--frames", frames, "strokes of the synthesised log (one KITTI frame each)")->capture_default_str();
  app.add_option("--passes", passes, "times the log is replayed")->capture_default_str();
  app.add_option("--speed", speed, "replay speed (1 = as recorded)")->capture_default_str();
  app.add_option("--threads", threads, "detection threads (0 = all cores)")->capture_default_str();
  app.add_flag("--close-on-scan", closeOnScan,
               "close sweeps on the next stroke's first scan (fusion.close_on_tilt false), the rule before "
               "closing on the tilt sample that proves the turn: the peer for the close stage");
  app.add_option("--viewers", viewerCounts,
                 "after the run without the live view, one run per count with the live view on and that many "
                 "viewers subscribed to every channel, e.g. --viewers 0,1,5")
      ->delimiter(',');
  app.add_option("--neural", neuralKinds,
                 "after the runs above, one run per network kind with neural layers on (config section neural, input\n"
                 "832x256, the kind's default files in --networks): darknet (Yolo-Fastest-XL), yolov5-onnx (YOLOv5n),\n"
                 "e.g. --neural darknet,yolov5-onnx")
      ->delimiter(',')
      ->check(CLI::IsMember({"darknet", "yolov5-onnx"}));
  app.add_option("--networks", networks,
                 "folder with yolo-fastest-1.1-xl.cfg + .weights and yolov5n_256x832.onnx (YOLOv5n is AGPL-3.0:\n"
                 "user-supplied, never bundled)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const std::string loadAtStart = loadAverage();

  const fs::path tmp = fs::temp_directory_path() / ("fusedet-bench-" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  std::string scene = "log " + log;
  if (log.empty()) {
    fusion::SynthOptions synth;
    if (fs::exists(fs::path(data) / "kitti" / "velodyne")) synth.kitti = fs::path(data) / "kitti";
    synth.frames = frames;
    log = (tmp / "bench.mcap").string();
    const fusion::SynthReport r = fusion::synthesizeLog(synth, log);
    scene = "synthesised " + r.scene + ", " + std::to_string(r.frameIds.size()) + " strokes of " +
            std::to_string(r.strokeS).substr(0, 5) + " s";
  }

  Config config;
  config.socket.path = (tmp / "bench.sock").string();
  config.detection.models = {models + "/car.json", models + "/bike.json", models + "/person.json"};
  config.detection.threads = threads;
  config.replay.file = log;
  config.replay.realtime = true;
  config.replay.speed = speed;
  config.replay.restamp = true;  // stamps = when the sensor would have measured: latencies are real
  config.replay.atEnd = "loop";
  config.fusion.closeOnTilt = !closeOnScan;
  const Run run = replay(config, passes, -1);
  const std::vector<double>& latency = run.latency;
  const std::vector<double>& compute = run.compute;
  const std::vector<double>& deliver = run.deliver;
  const std::map<std::string, std::vector<double>>& stagesConst = run.stages;
  std::map<std::string, std::vector<double>> stages = stagesConst;
  const std::vector<std::string>& perStack = run.perStack;
  const PipelineCounters& c = run.counters;
  const nlohmann::json& status = run.status;
  const std::vector<ThreadCpu>& threadCpu = run.threadCpu;
  std::vector<std::pair<int, Run>> withViewers;
  for (int n : viewerCounts) withViewers.emplace_back(n, replay(config, passes, n));
  std::vector<std::pair<std::string, Run>> withNeural;
  for (const std::string& kind : neuralKinds) {
    Config neural = config;
    neural.neural.enabled = true;
    neural.neural.kind = kind;
    neural.neural.directory = networks;
    neural.neural.input = "832x256";
    try {
      withNeural.emplace_back(kind, replay(neural, passes, -1));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "bench_daemon_latency: --neural %s: %s\n", kind.c_str(), e.what());
      fs::remove_all(tmp);
      return 1;
    }
  }
  fs::remove_all(tmp);

  std::printf("daemon latency, replay: %s; %d passes at %.2fx recorded speed, re-stamped; classes car bike person, "
              "detection threads %d (0 = all), %u cores; sweeps close on %s\n",
              scene.c_str(), passes, speed, threads, std::thread::hardware_concurrency(),
              closeOnScan ? "the next scan (--close-on-scan)" : "the tilt sample that proves the turn (default)");
  std::printf("load average (/proc/loadavg 1/5/15 min) at start: %s, at end: %s\n", loadAtStart.c_str(),
              loadAverage().c_str());
  std::printf("detection's %s\n", boosting::vectorPathSummary().c_str());
  std::printf("stacks: %zu received by the client, %llu dropped by the stack queue (detection behind), %llu unpaired sweeps; "
              "sweeps %llu, closed by a tilt sample %llu\n",
              latency.size(), static_cast<unsigned long long>(c.stackQueue.dropped),
              static_cast<unsigned long long>(c.unpaired), static_cast<unsigned long long>(c.sweeps.sweeps),
              static_cast<unsigned long long>(c.sweeps.sweepsClosedOnTilt));
  for (const auto& [kind, r] : withNeural)
    if (r.latency.empty()) {
      std::fprintf(stderr, "bench_daemon_latency: with neural layers (%s) no stack reached the client: %s\n", kind.c_str(),
                   r.status.dump().c_str());
      return 1;
    }
  for (const auto& [n, r] : withViewers)
    if (r.latency.empty()) {
      std::fprintf(stderr, "bench_daemon_latency: with %d viewers no stack reached the client: %s\n", n, r.status.dump().c_str());
      return 1;
    }
  if (latency.empty()) {
    std::fprintf(stderr, "bench_daemon_latency: no stack reached the client: %s\n", status.dump().c_str());
    return 1;
  }
  std::printf("%-44s p50 %8.1f  p90 %8.1f  p99 %8.1f  max %8.1f ms\n", "sensor stamp -> socket client (ours)",
              percentile(latency, 0.5), percentile(latency, 0.9), percentile(latency, 0.99), percentile(latency, 1.0));
  std::printf("%-44s p50 %8.1f  p90 %8.1f  p99 %8.1f  max %8.1f ms\n", "fuse + detect only, same stacks (floor)",
              percentile(compute, 0.5), percentile(compute, 0.9), percentile(compute, 0.99), percentile(compute, 1.0));
  // Nearest rank (daemon::percentile): p99 of 100 or fewer values is the largest; the largest of n
  // values sits near the n/(n+1) quantile, so few stacks make an optimistic p99.
  if (latency.size() <= 100)
    std::printf("(p99 of %zu stacks = the slowest one; more than 100 stacks, e.g. --passes 17 of 6 strokes, for one that is not)\n",
                latency.size());
  auto row = [](const char* what, const std::vector<double>& v) {
    std::printf("  %-42s p50 %8.1f  p90 %8.1f  p99 %8.1f  max %8.1f ms\n", what, percentile(v, 0.5),
                percentile(v, 0.9), percentile(v, 0.99), percentile(v, 1.0));
  };
  std::printf("per stage (wall unless cpu = the thread's own CPU time):\n");
  row("sensor stamp -> fusion starts (close)", stages["close"]);
  row("camera frame decode", stages["decode"]);
  row("fuse", stages["fuse"]);
  row("decode + fuse, fusion thread cpu", stages["fuse_cpu"]);
  row("stack queue", stages["queue"]);
  row("detect (3 classes)", stages["detect"]);
  row("detect, detection thread cpu", stages["detect_cpu"]);
  row("localize", stages["localize"]);
  row("detection done -> client receives", deliver);
  std::printf("per stack, ms: stack latency close decode+fuse fuse_cpu queue detect detect_cpu deliver detections\n");
  for (const std::string& r : perStack) std::printf("%s\n", r.c_str());
  std::printf("CPU time per thread during the replay, ms (fd-* = the daemon's threads, fd-tbb = TBB workers helping detection; others: the bench's client):\n");
  for (const ThreadCpu& t : threadCpu)
    if (t.cpuMs > 0) std::printf("  %-16s %9.1f\n", t.name.c_str(), t.cpuMs);
  if (!withViewers.empty()) {
    std::printf("live view (every channel subscribed by each viewer; a viewer reads as fast as it can):\n");
    std::printf("  %-22s %7s %8s %8s %8s %8s %7s %7s %9s %9s %7s %8s\n", "run", "stacks", "p50", "p90", "p99", "max",
                "q-drop", "skipped", "msgs/s", "MB/s", "v-drop", "live_cpu");
    auto tableRow = [](const std::string& what, const Run& r) {
      const nlohmann::json& l = r.status["live"];
      const double viewersMb = static_cast<double>(r.viewerBytes) / 1e6 / std::max(r.seconds, 1e-9);
      const double liveCpu = threadCpuOf(r, "fd-live");
      std::printf("  %-22s %7zu %8.1f %8.1f %8.1f %8.1f %7llu %7llu %9.1f %9.2f %7d %8.0f\n", what.c_str(), r.latency.size(),
                  percentile(r.latency, 0.5), percentile(r.latency, 0.9), percentile(r.latency, 0.99), percentile(r.latency, 1.0),
                  static_cast<unsigned long long>(r.counters.stackQueue.dropped),
                  static_cast<unsigned long long>(l.is_null() ? 0 : l["stacks_skipped"].get<std::uint64_t>()),
                  static_cast<double>(r.viewerMessages) / std::max(r.seconds, 1e-9), viewersMb, r.viewersDropped, liveCpu);
    };
    tableRow("live view off", run);
    for (const auto& [n, r] : withViewers) tableRow("live on, " + std::to_string(n) + " viewer" + (n == 1 ? "" : "s"), r);
    std::printf("  (ms: sensor stamp -> socket client; q-drop: stacks the stack queue dropped; skipped: stacks the live "
                "thread never took (a newer one came first); MB/s: all viewers together; v-drop: viewers disconnected as too slow; "
                "live_cpu: the fd-live thread's CPU ms)\n");
    for (const auto& [n, r] : withViewers) {
      if (r.latency.empty()) continue;
      std::printf("bench: live_%d_viewers_latency_p50_ms %.1f\n", n, percentile(r.latency, 0.5));
      std::printf("bench: live_%d_viewers_latency_p99_ms %.1f\n", n, percentile(r.latency, 0.99));
    }
  }
  if (!withNeural.empty()) {
    std::printf("neural layers (config section neural, 832x256, the network on its own thread fd-network, 1 OpenCV thread):\n");
    std::printf("  %-30s %7s %8s %8s %8s %8s %7s %7s %8s %8s %8s %9s\n", "run", "stacks", "p50", "p90", "p99", "max", "q-drop",
                "n-drop", "net p50", "net p99", "net cpu", "fd-network");
    auto neuralRow = [](const std::string& what, const Run& r) {
      const auto& st = r.stages;
      const auto stage = [&](const char* k) { return st.count(k) ? st.at(k) : std::vector<double>{}; };
      const double networkCpu = threadCpuOf(r, "fd-network");
      std::printf("  %-30s %7zu %8.1f %8.1f %8.1f %8.1f %7llu %7llu %8.1f %8.1f %8.1f %9.0f\n", what.c_str(), r.latency.size(),
                  percentile(r.latency, 0.5), percentile(r.latency, 0.9), percentile(r.latency, 0.99), percentile(r.latency, 1.0),
                  static_cast<unsigned long long>(r.counters.stackQueue.dropped),
                  static_cast<unsigned long long>(r.counters.networkQueue.dropped), percentile(stage("neural"), 0.5),
                  percentile(stage("neural"), 0.99), percentile(stage("neural_cpu"), 0.5), networkCpu);
    };
    neuralRow("no neural layers", run);
    for (const auto& [kind, r] : withNeural)
      neuralRow(kind == "darknet" ? "Yolo-Fastest-XL (darknet)" : "YOLOv5n (yolov5-onnx)", r);
    std::printf("  (ms: sensor stamp -> socket client; q-drop: stacks the stack queue dropped; n-drop: stacks the network queue\n"
                "  dropped, never run through the network; net: the network's run + score layers per stack, wall, and the\n"
                "  network thread's CPU ms (p50); fd-network: that thread's CPU ms over the run)\n");
    for (const auto& [kind, r] : withNeural) {
      const std::string key = kind == "darknet" ? "darknet" : "yolov5n";
      const auto neuralMs = r.stages.count("neural") ? r.stages.at("neural") : std::vector<double>{};
      std::printf("bench: neural_%s_latency_p50_ms %.1f\n", key.c_str(), percentile(r.latency, 0.5));
      std::printf("bench: neural_%s_latency_p99_ms %.1f\n", key.c_str(), percentile(r.latency, 0.99));
      std::printf("bench: neural_%s_network_p50_ms %.1f\n", key.c_str(), percentile(neuralMs, 0.5));
      std::printf("bench: neural_%s_network_queue_dropped %llu\n", key.c_str(),
                  static_cast<unsigned long long>(r.counters.networkQueue.dropped));
      std::printf("bench: neural_%s_stacks %zu\n", key.c_str(), r.latency.size());
    }
  }
  std::printf("bench: compute_p50_ms %.1f\n", percentile(compute, 0.5));
  std::printf("bench: compute_p99_ms %.1f\n", percentile(compute, 0.99));
  std::printf("bench: close_p50_ms %.1f\n", percentile(stages["close"], 0.5));
  std::printf("bench: fuse_cpu_p50_ms %.1f\n", percentile(stages["fuse_cpu"], 0.5));
  std::printf("bench: detect_p50_ms %.1f\n", percentile(stages["detect"], 0.5));
  std::printf("bench: detect_cpu_p50_ms %.1f\n", percentile(stages["detect_cpu"], 0.5));
  std::printf("bench: latency_p50_ms %.1f\n", percentile(latency, 0.5));
  std::printf("bench: latency_p99_ms %.1f\n", percentile(latency, 0.99));
  return 0;
}
