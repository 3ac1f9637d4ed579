// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/tilt_drive.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

namespace fusedet::drivers::canopen {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
std::int64_t ns(std::chrono::nanoseconds d) { return d.count(); }
std::string hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, v);
  return buf;
}
}  // namespace

std::string TiltDriveConfig::validate() const {
  if (node < 1 || node > 127) return "tilt: node id must be 1..127";
  if (!(minDeg < maxDeg)) return "tilt: min_deg must be below max_deg";
  if (!(speedDegS > 0)) return "tilt: speed_deg_s must be positive";
  if (units.countsPerRev < 1 || !(units.gearRatio > 0)) return "tilt: counts_per_rev and gear_ratio must be positive";
  if (heartbeatMs < 1 || heartbeatMs > 65535) return "tilt: heartbeat_ms must be 1..65535";
  if (syncPeriod.count() < 1) return "tilt: SYNC period must be at least 1 ms";
  const double limit = std::abs(units.toRad(std::numeric_limits<std::int32_t>::max() / 2)) / kDeg;
  if (std::abs(minDeg) > limit || std::abs(maxDeg) > limit) return "tilt: angles exceed the drive's position range";
  return {};
}

std::string_view toString(TiltPhase p) {
  switch (p) {
    case TiltPhase::kIdle: return "idle";
    case TiltPhase::kBooting: return "booting";
    case TiltPhase::kConfiguring: return "configuring";
    case TiltPhase::kEnabling: return "enabling";
    case TiltPhase::kRunning: return "running";
    case TiltPhase::kFault: return "fault";
    case TiltPhase::kStopping: return "stopping";
    case TiltPhase::kStopped: return "stopped";
  }
  return "unknown";
}

TiltDrive::TiltDrive(CanBus& bus, TiltDriveConfig config, SampleHandler onSample)
    : bus_(bus), config_(std::move(config)), onSample_(std::move(onSample)), sdo_(bus, config_.node, config_.sdoTimeout),
      tpdo_(config_.node, config_.units) {}

void TiltDrive::setFaultHandler(FaultHandler h) {
  std::lock_guard lock(mutex_);
  onFault_ = std::move(h);
}

void TiltDrive::setEventHandler(EventHandler h) {
  std::lock_guard lock(mutex_);
  onEvent_ = std::move(h);
}

double TiltDrive::minRad() const { return config_.minDeg * kDeg; }
double TiltDrive::maxRad() const { return config_.maxDeg * kDeg; }

void TiltDrive::setFilters() {
  const auto n = static_cast<std::uint32_t>(config_.node);
  auto r = bus_.setFilters({{cob::kEmcy + n, 0x7FF}, {cob::kTpdo1 + n, 0x7FF}, {cob::kSdoTx + n, 0x7FF}, {cob::kHeartbeat + n, 0x7FF}});
  if (!r) spdlog::warn("tilt {}: {}", bus_.name(), r.error().message());
}

void TiltDrive::start() {
  std::lock_guard lock(mutex_);
  startRequested_ = true;
}

void TiltDrive::nod() {
  std::lock_guard lock(mutex_);
  motion_ = Motion::kNod;
  positioned_ = false;
  if (phase_ == TiltPhase::kRunning && move_ == MoveStep::kNone) beginMove();
}

void TiltDrive::hold(double angleRad) {
  std::lock_guard lock(mutex_);
  motion_ = Motion::kHold;
  holdRad_ = angleRad;
  if (phase_ == TiltPhase::kRunning && move_ != MoveStep::kCommanding) beginMove();
}

void TiltDrive::stop() {
  std::lock_guard lock(mutex_);
  if (phase_ == TiltPhase::kIdle || phase_ == TiltPhase::kStopped) {
    if (phase_ == TiltPhase::kIdle) stopConfirmed_ = true;  // never started: nothing to bring to rest
    phase_ = TiltPhase::kStopped;
    return;
  }
  ++generation_;
  sdo_.cancelAll(makeError(std::errc::operation_canceled, "stopping"));
  phase_ = TiltPhase::kStopping;
  haltAcked_ = stopConfirmed_ = false;
  phaseDeadline_ = now_ + ns(config_.stopTimeout());
  const std::uint64_t gen = generation_;
  auto halted = [this, gen](Result<SdoClient::Bytes> r) {
    if (gen == generation_ && r) haltAcked_ = true;
  };
  auto finish = [this, gen](Result<SdoClient::Bytes> r) {
    if (gen != generation_) return;
    (void)bus_.send(nmtFrame(NmtCommand::kPreOperational, config_.node));
    stopConfirmed_ = haltAcked_ && static_cast<bool>(r);
    phase_ = TiltPhase::kStopped;
  };
  sdo_.download(od::kControlword, 0, cw::kEnableOperation | cw::kHalt, 2, halted);
  sdo_.download(od::kControlword, 0, cw::kShutdown, 2, finish);
}

bool TiltDrive::stopConfirmed() const {
  std::lock_guard lock(mutex_);
  return phase_ == TiltPhase::kStopped && stopConfirmed_;
}

TiltPhase TiltDrive::phase() const {
  std::lock_guard lock(mutex_);
  return phase_;
}

bool TiltDrive::idleAtTarget() const {
  std::lock_guard lock(mutex_);
  return phase_ == TiltPhase::kRunning && move_ == MoveStep::kNone;
}

TiltDriveCounters TiltDrive::counters() const {
  std::lock_guard lock(mutex_);
  TiltDriveCounters c = counters_;
  c.sdo = sdo_.counters();
  c.phase = phase_;
  return c;
}

std::function<void(Result<SdoClient::Bytes>)> TiltDrive::expectOk(std::function<void(SdoClient::Bytes)> then) {
  const std::uint64_t gen = generation_;
  return [this, gen, then = std::move(then)](Result<SdoClient::Bytes> r) {
    if (gen != generation_) return;
    if (!r) return onSdoError(gen, r.error());
    if (then) then(std::move(*r));
  };
}

void TiltDrive::onSdoError(std::uint64_t generation, const Error& e) {
  if (generation != generation_) return;
  fault(e.message(), e.code != std::errc::timed_out);
}

void TiltDrive::fault(const std::string& cause, bool reachable) {
  if (phase_ == TiltPhase::kStopping || phase_ == TiltPhase::kStopped || phase_ == TiltPhase::kIdle) return;
  ++generation_;
  // A failure while recovering (or while already in fault) is a failed retry, not a new fault.
  const bool retryFailed = phase_ == TiltPhase::kFault || recovering_;
  sdo_.cancelAll(makeError(std::errc::operation_canceled, "fault: " + cause));
  if (!retryFailed) {
    ++counters_.faults;
    faultAt_ = now_;
    counters_.lastFault = cause;
    heartbeatFault_ = cause.find("heartbeat") != std::string::npos;
    spdlog::warn("tilt {} node {}: fault: {}", bus_.name(), config_.node, cause);
    if (onFault_) onFault_(cause);
    TiltEvent e;
    e.kind = TiltEvent::Kind::kFault;
    e.cause = cause;
    emit(e);
  } else {
    spdlog::info("tilt {} node {}: recovery failed: {}", bus_.name(), config_.node, cause);
  }
  phase_ = TiltPhase::kFault;
  move_ = MoveStep::kNone;
  positioned_ = false;
  heardSinceFault_ = false;
  backoff_ = retryFailed ? std::min(config_.retryMax, std::max(config_.retryMin, backoff_ * 2)) : config_.retryMin;
  retryAt_ = now_ + ns(backoff_);
  // Stop the sweep: halt (a drive in fault has stopped already; one that cannot hear us, too).
  if (reachable && !heartbeatFault_ && !retryFailed) sdo_.download(od::kControlword, 0, cw::kEnableOperation | cw::kHalt, 2, {});
}

void TiltDrive::beginConfigure() {
  phase_ = TiltPhase::kConfiguring;
  const auto n = static_cast<std::uint32_t>(config_.node);
  const TiltUnits& u = config_.units;
  sdo_.upload(od::kDeviceType, 0, expectOk([this](SdoClient::Bytes b) {
    const std::uint32_t type = b.size() >= 2 ? readLe(b, 0, static_cast<int>(std::min<std::size_t>(b.size(), 4))) : 0;
    if ((type & 0xFFFF) != 402) fault("node " + std::to_string(config_.node) + " is not a CiA 402 drive (device type " + hex(type, 8) + ")");
  }));
  sdo_.upload(od::kDeviceName, 0, expectOk([this](SdoClient::Bytes b) { counters_.deviceName.assign(b.begin(), b.end()); }));
  sdo_.download(od::kHeartbeatProducer, 0, static_cast<std::uint32_t>(config_.heartbeatMs), 2, expectOk([this](SdoClient::Bytes) {
    heartbeatArmed_ = true;
    lastHeartbeat_ = now_;
  }));
  sdo_.download(od::kTpdo1Comm, 1, 0x80000000u | (cob::kTpdo1 + n), 4, expectOk());
  sdo_.download(od::kTpdo1Comm, 2, 1, 1, expectOk());  // on every SYNC
  sdo_.download(od::kTpdo1Map, 0, 0, 1, expectOk());
  sdo_.download(od::kTpdo1Map, 1, 0x60640020, 4, expectOk());  // position actual, 32 bit
  sdo_.download(od::kTpdo1Map, 2, 0x60410010, 4, expectOk());  // statusword, 16 bit
  sdo_.download(od::kTpdo1Map, 0, 2, 1, expectOk());
  sdo_.download(od::kTpdo1Comm, 1, cob::kTpdo1 + n, 4, expectOk());
  sdo_.download(od::kModeOfOperation, 0, static_cast<std::uint32_t>(od::kProfilePositionMode), 1, expectOk());
  sdo_.download(od::kFollowingErrorWindow, 0, u.rate(config_.followingErrorDeg * kDeg), 4, expectOk());
  sdo_.download(od::kProfileVelocity, 0, u.rate(config_.speedDegS * kDeg), 4, expectOk());
  sdo_.download(od::kProfileAcceleration, 0, u.rate(config_.accelDegS2 * kDeg), 4, expectOk());
  sdo_.download(od::kProfileDeceleration, 0, u.rate(config_.accelDegS2 * kDeg), 4, expectOk([this](SdoClient::Bytes) {
    (void)bus_.send(nmtFrame(NmtCommand::kStart, config_.node));
    beginEnable();
  }));
}

void TiltDrive::beginEnable() {
  phase_ = TiltPhase::kEnabling;
  enableSteps_ = 0;
  enableStep();
}

// One step of the CiA 402 state machine toward operation enabled: read the statusword, send the
// controlword for the next transition, repeat.
void TiltDrive::enableStep() {
  sdo_.upload(od::kStatusword, 0, expectOk([this](SdoClient::Bytes b) {
    if (b.size() < 2) return fault("statusword upload returned " + std::to_string(b.size()) + " bytes");
    const auto s = static_cast<std::uint16_t>(readLe(b, 0, 2));
    counters_.statusword = s;
    const DriveState state = decodeStatusword(s);
    if (state == DriveState::kOperationEnabled) {
      phase_ = TiltPhase::kRunning;
      backoff_ = std::chrono::milliseconds(0);
      if (recovering_) {
        recovering_ = false;
        ++counters_.recoveries;
        counters_.lastRecoverySeconds = static_cast<double>(now_ - faultAt_) * 1e-9;
        spdlog::info("tilt {} node {}: recovered in {:.3f} s", bus_.name(), config_.node, counters_.lastRecoverySeconds);
        TiltEvent e;
        e.kind = TiltEvent::Kind::kRecovered;
        e.seconds = counters_.lastRecoverySeconds;
        emit(e);
      }
      if (!everEnabled_) {
        everEnabled_ = true;
        TiltEvent e;
        e.kind = TiltEvent::Kind::kOperationEnabled;
        e.seconds = static_cast<double>(now_ - startedAt_) * 1e-9;
        emit(e);
      }
      positioned_ = false;
      beginMove();
      return;
    }
    if (++enableSteps_ > 12) return fault("drive does not reach operation enabled (stuck in " + std::string(toString(state)) + ")");
    std::uint16_t next = 0;
    switch (state) {
      case DriveState::kFault:
        // Fault reset acts on the rising edge of bit 7: clear it first.
        sdo_.download(od::kControlword, 0, cw::kDisableVoltage, 2, expectOk());
        next = cw::kFaultReset;
        break;
      case DriveState::kSwitchOnDisabled: next = cw::kShutdown; break;
      case DriveState::kReadyToSwitchOn: next = cw::kSwitchOn; break;
      case DriveState::kSwitchedOn: next = cw::kEnableOperation; break;
      case DriveState::kQuickStopActive: next = cw::kDisableVoltage; break;
      default:  // not ready / fault reaction: the drive moves on by itself; ask again
        next = 0xFFFF;
        break;
    }
    if (next != 0xFFFF) sdo_.download(od::kControlword, 0, next, 2, expectOk());
    enableStep();
  }));
}

void TiltDrive::beginMove() {
  double target = holdRad_;
  if (motion_ == Motion::kNod) {
    if (!positioned_) {
      // First go to the nearer end; from there every move is a full sweep.
      const double at = tpdo_.last() ? tpdo_.last()->angle : 0.0;
      nextToMax_ = std::abs(at - maxRad()) < std::abs(at - minRad());
    }
    target = nextToMax_ ? maxRad() : minRad();
  }
  moveTarget_ = config_.units.toCounts(target);
  move_ = MoveStep::kCommanding;
  sweepSamples_ = 0;
  sweepMin_ = sweepMax_ = tpdo_.last() ? tpdo_.last()->angle : 0.0;
  ackPolls_ = 0;
  sdo_.download(od::kTargetPosition, 0, static_cast<std::uint32_t>(moveTarget_), 4, expectOk());
  sdo_.download(od::kControlword, 0, cw::kEnableOperation | cw::kNewSetPoint | cw::kChangeImmediately, 2, expectOk());
  awaitSetPointAck();
}

// Polls the statusword until the drive acknowledges the set-point (bit 12), then clears the
// new-set-point bit; from then on the TPDO's target-reached bit ends the move.
void TiltDrive::awaitSetPointAck() {
  sdo_.upload(od::kStatusword, 0, expectOk([this](SdoClient::Bytes b) {
    const auto s = static_cast<std::uint16_t>(b.size() >= 2 ? readLe(b, 0, 2) : 0);
    counters_.statusword = s;
    if (!(s & sw::kSetPointAck)) {
      if (++ackPolls_ > 20) return fault("drive does not acknowledge the new set-point (statusword " + hex(s, 4) + ")");
      return awaitSetPointAck();
    }
    sdo_.download(od::kControlword, 0, cw::kEnableOperation | cw::kChangeImmediately, 2,
                  expectOk([this](SdoClient::Bytes) { move_ = MoveStep::kAwaitReached; }));
  }));
}

void TiltDrive::handleHeartbeat(const CanFrame& f) {
  if (f.len < 1) return;
  ++counters_.heartbeats;
  lastHeartbeat_ = f.stamp;
  heardSinceFault_ = true;
  auto state = parseNmtState(f.data[0]);
  if (!state) return;
  if (*state == NmtState::kBootUp) {
    ++counters_.bootUps;
    heartbeatArmed_ = false;  // a rebooted node produces no heartbeat until configured again
    if (phase_ == TiltPhase::kBooting) return beginConfigure();
    if (phase_ != TiltPhase::kFault) fault("node " + std::to_string(config_.node) + " rebooted (boot-up message)");
    return;
  }
  if ((phase_ == TiltPhase::kRunning) && *state != NmtState::kOperational)
    fault("node " + std::to_string(config_.node) + " left operational state (now " + std::string(toString(*state)) + ")");
}

void TiltDrive::handleEmcy(const CanFrame& f) {
  auto e = parseEmcy(f);
  if (!e) return;
  ++counters_.emcys;
  counters_.lastEmcyCode = e->code;
  if (e->code == 0) {
    spdlog::info("tilt {} node {}: {}", bus_.name(), config_.node, describe(*e));
    return;  // error reset: the answer to our fault reset
  }
  if (phase_ == TiltPhase::kBooting || phase_ == TiltPhase::kIdle) return;
  fault(describe(*e));
}

void TiltDrive::handleTpdo(const CanFrame& f) {
  const std::optional<TiltTpdo> t = tpdo_.decode(f);
  if (!t) {
    ++counters_.badPdos;
    return;
  }
  const std::uint16_t s = t->statusword;
  counters_.statusword = s;
  const TiltSample& sample = t->sample;
  ++counters_.samples;
  ++sweepSamples_;
  sweepMin_ = std::min(sweepMin_, sample.angle);
  sweepMax_ = std::max(sweepMax_, sample.angle);
  if (onSample_) onSample_(sample);

  if (phase_ != TiltPhase::kRunning) return;
  const DriveState state = decodeStatusword(s);
  if (s & sw::kFollowingError) return fault("following error (statusword " + hex(s, 4) + ")");
  if (state == DriveState::kFault || state == DriveState::kFaultReactionActive)
    return fault("drive fault (statusword " + hex(s, 4) + ")");
  if (state != DriveState::kOperationEnabled)
    return fault("drive left operation enabled (now " + std::string(toString(state)) + ")");
  if (move_ == MoveStep::kAwaitReached && (s & sw::kTargetReached) && !(s & sw::kSetPointAck)) {
    move_ = MoveStep::kNone;
    ++counters_.moves;
    if (motion_ == Motion::kNod) {
      if (positioned_) {
        ++counters_.sweeps;
        TiltEvent e;
        e.kind = TiltEvent::Kind::kSweep;
        e.index = counters_.sweeps;
        e.minRad = sweepMin_;
        e.maxRad = sweepMax_;
        e.samples = sweepSamples_;
        emit(e);
      }
      positioned_ = true;
      nextToMax_ = !nextToMax_;
      beginMove();
    }
  }
}

void TiltDrive::onFrame(const CanFrame& f) {
  std::lock_guard lock(mutex_);
  if (f.error) {
    ++counters_.errorFrames;
    spdlog::warn("tilt {}: CAN error frame: {}", bus_.name(), describeErrorFrame(f));
    return;
  }
  if (f.rtr || f.extended || phase_ == TiltPhase::kIdle) return;
  if (sdo_.onFrame(f)) return;
  const auto n = static_cast<std::uint32_t>(config_.node);
  if (f.id == cob::kHeartbeat + n) handleHeartbeat(f);
  else if (f.id == cob::kEmcy + n) handleEmcy(f);
  else if (tpdo_.isTpdo(f)) handleTpdo(f);
}

void TiltDrive::poll(Stamp now) {
  std::lock_guard lock(mutex_);
  now_ = now;
  if (startRequested_) {
    // (Re)start from scratch, e.g. after the caller reopened a failed bus: drop what was pending.
    startRequested_ = false;
    ++generation_;
    sdo_.cancelAll(makeError(std::errc::operation_canceled, "restart"));
    recovering_ = false;
    move_ = MoveStep::kNone;
    positioned_ = false;
    setFilters();
    phase_ = TiltPhase::kBooting;
    startedAt_ = now;
    phaseDeadline_ = now + ns(config_.bootTimeout);
    nextSync_ = now;
    heartbeatArmed_ = false;
    (void)bus_.send(nmtFrame(NmtCommand::kResetNode, config_.node));
  }
  if (phase_ == TiltPhase::kIdle || phase_ == TiltPhase::kStopped) return;
  sdo_.poll(now);
  if (phase_ == TiltPhase::kStopping && now >= phaseDeadline_) phase_ = TiltPhase::kStopped;
  if (phase_ == TiltPhase::kStopped) return;
  if (now >= nextSync_ && phase_ != TiltPhase::kStopping) {
    if (bus_.send(syncFrame())) ++counters_.syncs;
    nextSync_ = nextSync_ + ns(config_.syncPeriod);
    if (nextSync_ <= now) nextSync_ = now + ns(config_.syncPeriod);  // late: keep the period, skip the missed
  }
  if (phase_ == TiltPhase::kBooting && now >= phaseDeadline_) {
    // No boot-up (already running and missed it, or not there): try configuring; a missing
    // node then fails on its first SDO and is retried with back-off.
    spdlog::info("tilt {} node {}: no boot-up message within {} ms", bus_.name(), config_.node, config_.bootTimeout.count());
    recovering_ = false;
    beginConfigure();
  }
  const std::int64_t lossNs = static_cast<std::int64_t>(config_.heartbeatLossPeriods * config_.heartbeatMs * 1e6);
  if (heartbeatArmed_ && phase_ != TiltPhase::kFault && phase_ != TiltPhase::kStopping && now - lastHeartbeat_ > lossNs) {
    heartbeatArmed_ = false;
    fault("heartbeat of node " + std::to_string(config_.node) + " lost (none for " +
          std::to_string((now - lastHeartbeat_) / 1'000'000) + " ms)");
  }
  if (phase_ == TiltPhase::kFault && now >= retryAt_ && sdo_.idle()) {
    // After heartbeat loss wait until the node is heard again (or try every retryMax anyway).
    if (heartbeatFault_ && !heardSinceFault_ && now - faultAt_ < ns(config_.retryMax)) return;
    ++generation_;
    recovering_ = true;
    heartbeatArmed_ = false;
    beginConfigure();
  }
}

}  // namespace fusedet::drivers::canopen
