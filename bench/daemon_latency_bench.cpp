// Sensor-stamp-to-socket latency of the whole daemon: real KITTI scenes (Velodyne turn + camera
// image) played into a running Service at a fixed period, fused, run through every bundled class
// cascade and received by a socket client, which measures (receive time - sensor stamp). Beside
// it, on the same stacks in the same run: the pipeline's pure compute (fuse + detect), the floor
// any queueing and socket overhead adds to.

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <thread>

#include "fusedet/daemon/client.h"
#include "fusedet/daemon/kitti_scenes.h"
#include "fusedet/daemon/scene_source.h"
#include "fusedet/daemon/service.h"
#include "fusedet/daemon/stats.h"

using namespace fusedet;
using namespace fusedet::daemon;

int main(int argc, char** argv) {
  CLI::App app{"bench_daemon_latency - sensor stamp to socket client latency of fusedetd's pipeline"};
  std::string data = FUSEDET_DATA_DIR, models = FUSEDET_SOURCE_DIR "/models";
  int frames = 6, rounds = 5, periodMs = 200, threads = 0;
  app.add_option("--data", data, "root of the shared data")->capture_default_str();
  app.add_option("--models", models, "folder with car.json, bike.json, person.json")->capture_default_str();
  app.add_option("--frames", frames, "KITTI frames (held-back third of drive kitti)")->capture_default_str();
  app.add_option("--rounds", rounds, "times the frames are played")->capture_default_str();
  app.add_option("--period-ms", periodMs, "one scene every this many ms")->capture_default_str();
  app.add_option("--threads", threads, "detection threads (0 = all cores)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const auto root = std::filesystem::path(data) / "kitti";
  auto ids = fusion::listKittiFrames(root);
  std::vector<std::string> chosen;
  for (std::size_t i = ids.size() * 2 / 3; i < ids.size() && chosen.size() < static_cast<std::size_t>(frames); ++i)
    chosen.push_back(ids[i]);
  auto scenes = loadKittiScenes(root, chosen);

  Config config;
  config.socket.path = (std::filesystem::temp_directory_path() / ("fusedet-bench-" + std::to_string(::getpid()) + ".sock")).string();
  config.detection.models = {models + "/car.json", models + "/bike.json", models + "/person.json"};
  config.detection.threads = threads;
  ServiceParts parts;
  parts.config = config;
  parts.fuser = scenes.fuser;
  parts.detector = detectorFrom(config, {});
  auto source = std::make_unique<SceneSource>(scenes.scenes, std::chrono::milliseconds(periodMs), static_cast<std::size_t>(rounds));
  SceneSource* src = source.get();
  parts.sources.push_back(std::move(source));
  parts.listener = bindUnixSocket(config.socket.path);
  parts.mode = "scenes";
  Service service(std::move(parts));
  service.start();

  Client client(config.socket.path);
  client.send({{"cmd", "subscribe"}});
  std::vector<double> latency, compute;
  const std::size_t expected = chosen.size() * static_cast<std::size_t>(rounds);
  while (true) {
    auto line = client.readLine(std::chrono::seconds(20));
    if (!line) break;
    const Stamp received = Stamp::now();
    const auto m = nlohmann::json::parse(*line);
    if (m["type"] != "detections") continue;
    latency.push_back(static_cast<double>(received.ns - m["sensor_ns"].get<std::int64_t>()) * 1e-6);
    compute.push_back(m["fuse_ms"].get<double>() + m["detect_ms"].get<double>());
    const auto c = service.pipeline().counters();
    if (src->finished() && c.stacksDetected + c.stackQueue.dropped >= expected && latency.size() >= c.stacksDetected) break;
  }
  const auto c = service.pipeline().counters();
  service.stop(std::chrono::steady_clock::now() + std::chrono::milliseconds(1500));
  std::remove(config.socket.path.c_str());

  double load = 0;
  std::ifstream("/proc/loadavg") >> load;
  std::printf("daemon latency: %zu KITTI frames x %d rounds, one scene every %d ms, classes car bike person, "
              "detection threads %d (0 = all), %u cores, load average %.2f\n",
              chosen.size(), rounds, periodMs, threads, std::thread::hardware_concurrency(), load);
  std::printf("stacks: %zu received by the client, %llu dropped by the stack queue (detection behind)\n",
              latency.size(), static_cast<unsigned long long>(c.stackQueue.dropped));
  if (latency.empty()) {
    std::fprintf(stderr, "bench_daemon_latency: no stack reached the client\n");
    return 1;
  }
  std::printf("%-44s p50 %8.1f  p90 %8.1f  p99 %8.1f  max %8.1f ms\n", "sensor stamp -> socket client (ours)",
              percentile(latency, 0.5), percentile(latency, 0.9), percentile(latency, 0.99), percentile(latency, 1.0));
  std::printf("%-44s p50 %8.1f  p90 %8.1f  p99 %8.1f  max %8.1f ms\n", "fuse + detect only, same stacks (floor)",
              percentile(compute, 0.5), percentile(compute, 0.9), percentile(compute, 0.99), percentile(compute, 1.0));
  std::printf("bench: latency_p50_ms %.1f\n", percentile(latency, 0.5));
  std::printf("bench: latency_p99_ms %.1f\n", percentile(latency, 0.99));
  std::printf("bench: compute_p50_ms %.1f\n", percentile(compute, 0.5));
  return 0;
}
