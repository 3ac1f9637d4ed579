// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/service.h"

#include <grp.h>
#include <spdlog/spdlog.h>

#include <cstring>
#include <sstream>

#include "fusedet/boost/vector_path.h"
#include "fusedet/daemon/config_keys.h"
#include "fusedet/daemon/protocol.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/fusion/camera_model.h"

namespace fusedet::daemon {
namespace {

// The laser scans while the tilt stands still this long: the motor is parked, stuck or faulted
// (it pauses only a few ms at each end of a nod).
constexpr double kTiltStillS = 1.0;

const char* tiltMotion(const fusion::SweepStats& s) {
  if (s.tiltSamples == 0) return "no samples";
  return s.tiltStillS >= kTiltStillS ? "still" : "moving";
}

}  // namespace

std::shared_ptr<const fusion::Fuser> fuserFrom(const Config& config, const std::filesystem::path& configFile) {
  std::filesystem::path calibration = config.camera.calibration;
  if (calibration.is_relative()) calibration = configFile.parent_path() / calibration;
  return fuserFrom(config, fusion::readCameraModel(calibration), neuralLayersFrom(config, configFile));
}

std::shared_ptr<const fusion::NeuralLayers> neuralLayersFrom(const Config& config, const std::filesystem::path& configFile) {
  if (!config.neural.enabled) return nullptr;
  fusion::NeuralLayerOptions o;
  o.kind = fusion::parseNetworkKind(config.neural.kind);
  for (const std::string& f : config.neural.files) o.files.emplace_back(f);
  o.directory = config.neural.directory;
  if (o.directory.is_relative()) o.directory = configFile.parent_path() / o.directory;
  o.input = fusion::parseInputSize(config.neural.input);
  o.scale = config.neural.scale;
  o.threads = config.neural.threads;
  try {
    return std::make_shared<const fusion::NeuralLayers>(o);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("neural (network ") + config.neural.kind + " " + config.neural.input +
                             "): " + e.what());
  }
}

std::shared_ptr<const fusion::Fuser> fuserFrom(const Config& config, const fusion::CameraModel& camera,
                                               std::shared_ptr<const fusion::NeuralLayers> neural) {
  fusion::ProjectionConfig projection;
  projection.laserLayerScale = config.fusion.laserLayerScale;
  projection.holeFillRadius = config.fusion.holeFillRadius;
  return std::make_shared<const fusion::Fuser>(camera, laserToCamera(config), projection, std::move(neural));
}

namespace {
unsigned groupId(const std::string& name, const char* key) {
  std::vector<char> buf(16384);
  struct group g{};
  struct group* found = nullptr;
  const int rc = ::getgrnam_r(name.c_str(), &g, buf.data(), buf.size(), &found);
  if (rc != 0 || !found)
    throw std::runtime_error(std::string(key) + ": no group '" + name + "' on this machine" +
                             (rc ? std::string(" (") + std::strerror(rc) + ")" : ""));
  return found->gr_gid;
}
}  // namespace

SocketAccess socketAccessFrom(const Config& config) {
  SocketAccess a;
  a.mode = parseSocketMode(config.socket.mode).value_or(0660);
  if (!config.socket.group.empty()) a.group = groupId(config.socket.group, "socket.group");
  return a;
}

ServerLimits serverLimitsFrom(const Config& config) {
  ServerLimits l;
  for (const std::string& name : config.socket.allowGroups) l.allowGroups.emplace_back(name, groupId(name, "socket.allow_groups"));
  l.maxClients = config.socket.maxClients;
  l.maxRequestBytes = static_cast<std::size_t>(config.socket.maxRequestBytes);
  l.clientQueue = static_cast<std::size_t>(config.socket.clientQueue);
  l.clientSendBuffer = config.socket.clientSendBuffer;
  return l;
}

std::shared_ptr<const StackDetector> detectorFrom(const Config& config, const std::filesystem::path& configFile,
                                                  const fusion::Fuser& fuser) {
  return std::make_shared<const CascadeSet>(config.detection, configFile.parent_path(), fuser.stackLayers(),
                                            fuser.network());
}

PipelineSetup pipelineSetup(ServiceParts& parts) {
  const Config& sensors = parts.sensorConfig ? *parts.sensorConfig : parts.config;
  PipelineSetup setup;
  setup.fuser = std::move(parts.fuser);
  setup.sweep = sweepConfig(sensors);
  setup.maxPairSkewNs = std::int64_t{sensors.fusion.maxPairSkewMs} * 1'000'000;
  setup.lossless = parts.lossless;
  setup.tracking = parts.config.tracking;
  setup.pinDetection = parts.config.detection.threads == 0;
  return setup;
}

Service::Service(ServiceParts parts)
    : config_(parts.config),
      configFile_(std::move(parts.configFile)),
      mode_(std::move(parts.mode)),
      wallClockStamps_(parts.wallClockStamps),
      sources_(std::move(parts.sources)) {
  Server::Handlers handlers{[this] { return hello(); }, [this] { return status(); }};
  server_ = std::make_unique<Server>(std::move(parts.listener), serverLimitsFrom(config_), std::move(handlers));
  PipelineSetup setup = pipelineSetup(parts);
  if (const auto address = live::parseListenAddress(config_.live.listen)) {
    setup.keepViews = true;  // the live view draws the stacks' images and sweeps
    live::ChannelSettings channels{setup.fuser->projection(), config_.tracking.maxCoastS, config_.live.layers};
    live::LiveLimits limits{config_.live.maxViewers, static_cast<std::size_t>(config_.live.viewerQueueBytes)};
    live_ = std::make_unique<live::LiveServer>(*address, limits, live::LiveChannels(std::move(channels)), [this] { return status(); });
  }
  pipeline_ = std::make_unique<Pipeline>(std::move(setup), std::move(parts.detector), [this](std::shared_ptr<const StackResult> r) {
    if (live_) live_->publish(r);
    server_->publish(std::move(r));
  });
}

Service::~Service() { stop(std::chrono::steady_clock::now()); }

void Service::start() {
  startedNs_ = Stamp::now().ns;
  // spdlog's logger registry is made on first use; made here, before the threads that log at
  // their start (server, detection), they need not race to make it (ThreadSanitizer cannot see
  // the guard of that static inside libspdlog and reported the two first uses as a race).
  spdlog::default_logger_raw();
  server_->start();
  if (live_) live_->start();
  pipeline_->start();
  for (auto& s : sources_) s->start(*pipeline_);
  started_ = true;
}

std::string Service::stop(std::chrono::steady_clock::time_point deadline) {
  if (!started_) return {};
  started_ = false;
  std::string problems;
  for (auto& s : sources_) {
    s->stop();
    if (std::string p = s->stopProblem(); !p.empty()) problems += (problems.empty() ? "" : "; ") + p;
  }
  sourcesStopped_ = true;
  pipeline_->stop(deadline);
  if (live_) live_->stop();
  server_->stop(deadline);
  return problems;
}

std::chrono::milliseconds Service::stopBudget() const {
  // The pipeline drains while the sources stop; after the last one it gets a short while more.
  constexpr std::chrono::milliseconds kAfterSources{300};
  std::chrono::milliseconds sources{0};
  for (const auto& s : sources_) sources += s->stopTime();
  return std::max(kDrainBudget, sources + kAfterSources);
}

Config Service::config() const {
  std::lock_guard lock(mutex_);
  return config_;
}

std::string Service::reload() {
  if (configFile_.empty()) return "no config file to reload";
  Config next;
  try {
    next = loadConfig(configFile_);
  } catch (const std::exception& e) {  // ConfigError, and anything else: a bad file never ends the service
    std::lock_guard lock(mutex_);
    lastReloadError_ = e.what();
    return lastReloadError_;
  }
  return reload(next);
}

std::string Service::reload(const Config& next) {
  // The reloadable keys of `next` (config_keys.h reloadableConfigKeys()); what else changed needs a
  // restart (devices, socket path, fusion geometry).
  Config applied;
  std::shared_ptr<const StackDetector> detector;
  ServerLimits limits;
  try {
    applied = withReloaded(config(), next);
    limits = serverLimitsFrom(applied);  // socket.allow_groups may name a group that does not exist
    detector = detectorFrom(applied, configFile_, pipeline_->fuser());
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    lastReloadError_ = e.what();
    return lastReloadError_;
  }
  pipeline_->setDetector(std::move(detector));
  server_->setLimits(limits);
  spdlog::set_level(spdlog::level::from_str(applied.logLevel));
  if (dumpConfig(applied) != dumpConfig(next)) {
    std::string reloadable;
    for (const std::string& k : reloadableConfigKeys()) reloadable += (reloadable.empty() ? "" : ", ") + k;
    spdlog::warn("reload: changes outside {} take effect after a restart", reloadable);
  }
  std::lock_guard lock(mutex_);
  config_ = applied;
  lastReloadError_.clear();
  ++reloads_;
  return "";
}

nlohmann::json Service::hello() const {
  return {{"protocol", kProtocolVersion},
          {"version", FUSEDET_DAEMON_VERSION},
          {"mode", mode_},
          {"classes", pipeline_->detector()->classes()}};
}

nlohmann::json Service::status() const {
  const std::int64_t now = Stamp::now().ns;
  const PipelineCounters p = pipeline_->counters();
  const ServerCounters s = server_->counters();
  // Stamps ahead of the clock (as fast as possible, speed > 1) or in the past (not re-stamped)
  // would give meaningless, even negative, latencies: none is reported then.
  const LatencySummary lat = wallClockStamps_ ? server_->latency() : LatencySummary{};
  nlohmann::json sensors = nlohmann::json::array();
  for (const auto& src : sources_)
    for (const SensorHealth& h : src->health()) {
      nlohmann::json entry{{"name", h.name},
                           {"state", h.state},
                           {"messages", h.messages},
                           {"crc_errors", h.crcErrors},
                           {"reconnects", h.reconnects},
                           {"lost", h.lost},
                           {"last_error", h.lastError}};
      if (h.progress) {
        entry["progress"] = *h.progress;
        entry["passes"] = h.passes;
      }
      sensors.push_back(std::move(entry));
    }
  nlohmann::json peers = nlohmann::json::array();
  for (const Peer& peer : server_->peers())
    peers.push_back({{"client", peer.client}, {"pid", peer.pid}, {"uid", peer.uid}, {"gid", peer.gid}, {"subscribed", peer.subscribed}});
  nlohmann::json liveView = nullptr;  // null: live.listen is off
  if (live_) {
    const live::LiveCounters l = live_->counters();
    nlohmann::json encoded = nlohmann::json::object();
    const auto& channels = live_->channels();
    for (std::size_t i = 0; i < channels.size() && i < l.encoded.size(); ++i) encoded[channels[i].topic] = l.encoded[i];
    liveView = {{"listen", live_->address().text()},
                {"viewers", l.viewers},
                {"accepted", l.accepted},
                {"refused", l.refused},
                {"dropped_slow", l.droppedSlow},
                {"disconnected", l.disconnected},
                {"pages", l.pages},
                {"not_found", l.notFound},
                {"stacks", l.stacks},
                {"stacks_skipped", l.stacksSkipped},
                {"messages", l.messages},
                {"bytes", l.bytes},
                {"last_encode_ms", l.lastEncodeMs},
                {"encoded", std::move(encoded)}};
  }
  nlohmann::json network = nullptr;  // null: no network (config section neural off)
  if (p.network)
    network = {{"network", pipeline_->fuser().network().text()},
               {"queue", {{"depth", p.networkQueue.depth}, {"pushed", p.networkQueue.pushed}, {"dropped", p.networkQueue.dropped}}},
               {"runs", p.networkRuns},
               {"errors", p.networkErrors},
               {"failing", p.networkFailing},
               {"last_error", p.lastNetworkError},
               {"last_ms", p.lastNetworkMs},
               {"ms", {{"samples", p.networkMs.samples}, {"p50", p.networkMs.p50Ms}, {"p90", p.networkMs.p90Ms},
                       {"p99", p.networkMs.p99Ms}, {"max", p.networkMs.maxMs}}}};
  std::lock_guard lock(mutex_);
  return {
      {"mode", mode_},
      {"uptime_s", static_cast<double>(now - startedNs_) * 1e-9},
      {"classes", pipeline_->detector()->classes()},
      {"vector_path", boosting::vectorPathName(boosting::dispatchedVectorLanes())},
      {"sensors", std::move(sensors)},
      {"rates_hz", {{"scans", p.scanRate}, {"tilt", p.tiltRate}, {"frames", p.frameRate}, {"stacks", p.stackRate}}},
      {"pipeline",
       {{"sensor_queue", {{"depth", p.sensorQueue.depth}, {"pushed", p.sensorQueue.pushed}, {"dropped", p.sensorQueue.dropped}}},
        {"stack_queue", {{"depth", p.stackQueue.depth}, {"pushed", p.stackQueue.pushed}, {"dropped", p.stackQueue.dropped}}},
        {"sweeps", p.sweeps.sweeps},
        {"sweeps_cut", p.sweeps.sweepsCut},
        {"tilt_motion", tiltMotion(p.sweeps)},
        {"tilt_still_s", p.sweeps.tiltStillS},
        {"scans_dropped_no_tilt", p.sweeps.scansDroppedNoTilt},
        {"unpaired_sweeps", p.unpaired},
        {"decode_errors", p.decodeErrors},
        {"fuse_errors", p.fuseErrors},
        {"detect_errors", p.detectErrors},
        {"stacks_fused", p.stacksFused},
        {"stacks_detected", p.stacksDetected},
        {"detections", p.detections},
        {"last_fuse_ms", p.lastFuseMs},
        {"last_detect_ms", p.lastDetectMs},
        {"network", std::move(network)}}},
      {"latency_ms", {{"samples", lat.samples}, {"p50", lat.p50Ms}, {"p90", lat.p90Ms}, {"p99", lat.p99Ms}, {"max", lat.maxMs}}},
      {"clients",
       {{"connected", s.clients},
        {"accepted", s.accepted},
        {"refused", s.refused},
        {"dropped_slow", s.droppedSlow},
        {"disconnected", s.disconnected},
        {"bad_requests", s.badRequests},
        {"oversized_requests", s.oversized},
        {"refused_not_allowed", s.refusedNotAllowed},
        {"refused_no_fd", s.refusedNoFd},
        {"peers", peers}}},
      {"live", std::move(liveView)},
      {"reloads", reloads_},
      {"last_reload_error", lastReloadError_}};
}

bool Service::finished() const {
  if (sources_.empty()) return false;
  for (const auto& s : sources_)
    if (!s->finished()) return false;
  return pipeline_->idle();
}

bool Service::failed() const {
  for (const auto& s : sources_)
    if (s->failed()) return true;
  return false;
}

bool Service::alive(std::int64_t maxAgeNs) const { return stalled(maxAgeNs).empty(); }

std::string Service::stalled(std::int64_t maxAgeNs) const {
  const std::int64_t now = Stamp::now().ns;
  std::string out;
  for (const auto& [name, beat] : {std::pair{"fusion", pipeline_->fusionBeatNs()},
                                   std::pair{"network", pipeline_->networkBeatNs()},
                                   std::pair{"detection", pipeline_->detectionBeatNs()},
                                   std::pair{"server", server_->beatNs()}}) {
    if (std::string_view(name) == "network" && !pipeline_->hasNetworkThread()) continue;
    const std::int64_t age = now - beat;
    if (age < maxAgeNs) continue;
    const std::int64_t seconds = age / 1'000'000'000;
    out += (out.empty() ? "" : ", ") + std::string(name) + " thread stuck for " +
           (seconds ? std::to_string(seconds) : std::string("<1")) + " s";
  }
  return out;
}

std::string Service::summary() const {
  const PipelineCounters p = pipeline_->counters();
  const ServerCounters s = server_->counters();
  std::ostringstream o;
  o << mode_ << ": ";
  bool first = true;
  for (const auto& src : sources_)
    for (const SensorHealth& h : src->health()) {
      o << (first ? "" : ", ") << h.name << ' ' << h.state;
      if (h.progress) o << ' ' << static_cast<int>(*h.progress * 100) << '%';
      first = false;
    }
  if (tiltMotion(p.sweeps) == std::string("still"))
    o << "; tilt still for " << static_cast<int>(p.sweeps.tiltStillS) << " s (" << p.sweeps.sweepsCut << " sweeps cut)";
  o << "; " << p.stacksDetected << " stacks, " << p.stackQueue.dropped + p.networkQueue.dropped << " dropped; " << s.clients
    << " clients";
  if (p.networkFailing) o << "; network failing (" << p.networkErrors << " failed runs): " << p.lastNetworkError;
  std::lock_guard lock(mutex_);
  if (!lastReloadError_.empty()) o << "; reload failed: " << lastReloadError_;
  return o.str();
}

}  // namespace fusedet::daemon
