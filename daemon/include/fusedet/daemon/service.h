// SPDX-License-Identifier: Apache-2.0
#pragma once
// Service: the running daemon - sources, pipeline and socket server wired together, with the
// answers to `hello` and `status`, reload (SIGHUP) and the liveness the systemd watchdog is fed
// from. run.h drives it from signals and sd_notify.

#include <atomic>
#include <chrono>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/live/live_server.h"
#include "fusedet/daemon/pipeline.h"
#include "fusedet/daemon/server.h"
#include "fusedet/daemon/source.h"
#include "fusedet/daemon/stack_detector.h"
#include "fusedet/drivers/unique_fd.h"

namespace fusedet::daemon {

struct ServiceParts {
  Config config;
  std::filesystem::path configFile;  // reload() reads it again; empty = reload(Config) only
  std::shared_ptr<const fusion::Fuser> fuser;
  std::shared_ptr<const StackDetector> detector;
  std::vector<std::unique_ptr<Source>> sources;
  drivers::UniqueFd listener;  // bound and listening
  std::string mode = "live";   // "live" | "replay" | "scenes"
  // The laser, tilt, camera and fusion settings in effect when they are not `config`'s own
  // (replay: the log's rig, rig.h replayRig).
  std::optional<Config> sensorConfig;
  bool lossless = false;  // PipelineSetup::lossless (a log replayed as fast as possible)
  // Sensor stamps are the clock's "now" as data arrives (live, or a replay paced at speed 1 and
  // re-stamped): only then is sensor stamp -> client a latency (status latency_ms).
  bool wallClockStamps = true;
};

// Fusion settings (camera calibration file, extrinsics, laser layers) of a config; a relative
// calibration path is relative to the config file's folder. Throws std::runtime_error naming the
// calibration file on failure.
// With neural.enabled the fuser also makes the network's score layers (neuralLayersFrom).
std::shared_ptr<const fusion::Fuser> fuserFrom(const Config& config, const std::filesystem::path& configFile);
// The same with a camera model already read (replay: the log's camera.yaml) and the network (or none).
std::shared_ptr<const fusion::Fuser> fuserFrom(const Config& config, const fusion::CameraModel& camera,
                                               std::shared_ptr<const fusion::NeuralLayers> neural = {});
// The network of the config's neural section, loaded (null when neural.enabled is false); a
// relative neural.directory is relative to the config file's folder. Throws std::runtime_error
// naming the section and the file when it cannot be loaded (missing file, wrong kind or input size).
std::shared_ptr<const fusion::NeuralLayers> neuralLayersFrom(const Config& config,
                                                             const std::filesystem::path& configFile);
// Throw std::runtime_error naming the key when a group of socket.group / socket.allow_groups
// does not exist on this machine.
ServerLimits serverLimitsFrom(const Config& config);
SocketAccess socketAccessFrom(const Config& config);
// The pipeline the parts ask for: their fuser, sweep assembly and pairing of the sensors' rig
// (sensorConfig, else config), lossless as set, the tracker of config.tracking. Takes the fuser.
PipelineSetup pipelineSetup(ServiceParts& parts);
// Models resolve relative to the config file's folder; each must run on `fuser`'s stacks (its
// layers, and for neural layers its network: CascadeSet).
std::shared_ptr<const StackDetector> detectorFrom(const Config& config, const std::filesystem::path& configFile,
                                                  const fusion::Fuser& fuser);

class Service {
 public:
  explicit Service(ServiceParts parts);
  ~Service();
  Service(const Service&) = delete;
  Service& operator=(const Service&) = delete;

  // Starts the server, the live view, the pipeline threads and the sources: afterwards requests are served.
  void start();
  // Stops the sources (each takes up to its Source::stopTime(): a tilt motor is brought to rest
  // first), drains the pipeline and flushes clients, all by `deadline` when that is at least
  // stopBudget() away. Returns "" when every source stopped safely, else what did not (a motor
  // not confirmed at rest): the caller must not report success then.
  std::string stop(std::chrono::steady_clock::time_point deadline);
  // What a SIGTERM stop needs: the sources' stop times plus a drain, at least kDrainBudget.
  std::chrono::milliseconds stopBudget() const;
  static constexpr std::chrono::milliseconds kDrainBudget{800};
  // True once stop() has stopped every source (the pipeline and clients may still drain).
  bool sourcesStopped() const { return sourcesStopped_.load(); }

  // Re-reads the config file and the models. Returns "" when applied; else why the old
  // configuration is kept. The keys of config_keys.h reloadableConfigKeys() (detection settings and
  // models, socket limits and allow_groups, log level) take effect at once; the log says other
  // changes need a restart.
  std::string reload();
  std::string reload(const Config& next);

  nlohmann::json hello() const;
  nlohmann::json status() const;
  // True when the fusion, detection and server threads all showed life within maxAgeNs.
  bool alive(std::int64_t maxAgeNs) const;
  // "" when alive; else which threads showed no life within maxAgeNs and for how long, e.g.
  // "detection thread stuck for 3 s" (whole seconds, "<1 s" before the first: STATUS= changes
  // at most once a second).
  std::string stalled(std::int64_t maxAgeNs) const;
  // One line for systemd's STATUS=.
  std::string summary() const;
  // Every source is finite and has delivered everything, and the pipeline is idle: all results
  // have reached the server (a replayed log at its end).
  bool finished() const;
  // Some source ended on an error it could not recover from (a replayed log that failed under
  // the reader): the end of a replay is then no success (fusedetd exits 1).
  bool failed() const;

  Pipeline& pipeline() { return *pipeline_; }
  Server& server() { return *server_; }
  // The live view (config live.listen); nullptr when off.
  live::LiveServer* liveServer() { return live_.get(); }
  Config config() const;

 private:
  mutable std::mutex mutex_;  // config_, lastReloadError_
  Config config_;
  std::filesystem::path configFile_;
  std::string mode_;
  bool wallClockStamps_ = true;
  std::string lastReloadError_;
  std::uint64_t reloads_ = 0;
  std::vector<std::unique_ptr<Source>> sources_;
  std::unique_ptr<Server> server_;
  std::unique_ptr<live::LiveServer> live_;
  std::unique_ptr<Pipeline> pipeline_;
  std::int64_t startedNs_ = 0;
  bool started_ = false;
  std::atomic<bool> sourcesStopped_{false};
};

}  // namespace fusedet::daemon
