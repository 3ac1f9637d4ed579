// SPDX-License-Identifier: Apache-2.0
#include "motor_simulator.h"

#include <algorithm>
#include <cmath>

namespace fusedet::drivers::canopen::sim {

namespace {
constexpr std::uint32_t kDeviceType402 = 0x00020192;  // CiA 402, servo drive
constexpr std::uint32_t kPdoInvalid = 0x80000000u;

std::int32_t asInt(std::uint32_t v) { return static_cast<std::int32_t>(v); }
}  // namespace

MotorSimulator::MotorSimulator(CanBus& bus, MotorSimOptions options) : bus_(bus), options_(std::move(options)) {
  loadDeviceDefaults();
  loadCommunicationDefaults();
  profile_.reset(options_.initialPosition);
  actual_ = options_.initialPosition;
}

void MotorSimulator::loadCommunicationDefaults() {
  const auto n = static_cast<std::uint32_t>(options_.node);
  od_[key(od::kDeviceType, 0)] = {kDeviceType402, 4, false, false};
  od_[key(od::kErrorRegister, 0)] = {0, 1, false, false};
  od_[key(od::kHeartbeatProducer, 0)] = {options_.heartbeatMs, 2, true, false};
  od_[key(od::kTpdo1Comm, 0)] = {2, 1, false, false};
  od_[key(od::kTpdo1Comm, 1)] = {cob::kTpdo1 + n, 4, true, false};
  od_[key(od::kTpdo1Comm, 2)] = {0xFF, 1, true, false};  // event driven: never sent here
  od_[key(od::kTpdo1Map, 0)] = {1, 1, true, false};
  od_[key(od::kTpdo1Map, 1)] = {0x60410010, 4, true, false};
  for (std::uint8_t s = 2; s <= 8; ++s) od_[key(od::kTpdo1Map, s)] = {0, 4, true, false};
}

void MotorSimulator::loadDeviceDefaults() {
  od_[key(od::kErrorCode, 0)] = {0, 2, false, false};
  od_[key(od::kControlword, 0)] = {0, 2, true, true};
  od_[key(od::kStatusword, 0)] = {0, 2, false, true};
  od_[key(od::kModeOfOperation, 0)] = {0, 1, true, true};
  od_[key(od::kModeDisplay, 0)] = {0, 1, false, true};
  od_[key(od::kPositionActual, 0)] = {0, 4, false, true};
  od_[key(od::kFollowingErrorWindow, 0)] = {options_.followingErrorWindow, 4, true, false};
  od_[key(od::kVelocityActual, 0)] = {0, 4, false, true};
  od_[key(od::kTargetPosition, 0)] = {0, 4, true, true};
  od_[key(od::kMaxProfileVelocity, 0)] = {options_.maxVelocity, 4, true, false};
  od_[key(od::kProfileVelocity, 0)] = {options_.velocity, 4, true, false};
  od_[key(od::kProfileAcceleration, 0)] = {options_.acceleration, 4, true, false};
  od_[key(od::kProfileDeceleration, 0)] = {options_.acceleration, 4, true, false};
}

std::uint32_t MotorSimulator::get(std::uint16_t index, std::uint8_t sub) const {
  auto it = od_.find(key(index, sub));
  return it == od_.end() ? 0 : it->second.value;
}
void MotorSimulator::set(std::uint16_t index, std::uint8_t sub, std::uint32_t v) { od_[key(index, sub)].value = v; }

void MotorSimulator::send(const CanFrame& f) {
  if (silent_ || inBusOff_ || booting_) return;
  if (bus_.send(f)) ++counters_.framesOut;
  else ++counters_.sendFailures;
}

void MotorSimulator::boot(bool wholeDictionary) {
  booting_ = true;
  bootWhole_ = wholeDictionary;
  bootAt_ = now_ + std::chrono::nanoseconds(options_.bootTime).count();
  segmenting_ = false;
}

void MotorSimulator::onFrame(const CanFrame& f) {
  std::lock_guard lock(mutex_);
  if (silent_ || inBusOff_ || booting_ || f.error || f.rtr || f.extended) return;
  ++counters_.framesIn;
  const auto n = static_cast<std::uint32_t>(options_.node);
  if (f.id == cob::kNmt) handleNmt(f);
  else if (f.id == cob::kSync) handleSync();
  else if (f.id == cob::kSdoRx + n) handleSdo(f);
}

void MotorSimulator::handleNmt(const CanFrame& f) {
  if (f.len < 2 || (f.data[1] != 0 && f.data[1] != options_.node)) return;
  switch (static_cast<NmtCommand>(f.data[0])) {
    case NmtCommand::kStart: nmt_ = NmtState::kOperational; break;
    case NmtCommand::kStop: nmt_ = NmtState::kStopped; break;
    case NmtCommand::kPreOperational: nmt_ = NmtState::kPreOperational; break;
    case NmtCommand::kResetNode: boot(true); break;
    case NmtCommand::kResetCommunication: boot(false); break;
  }
}

void MotorSimulator::handleSync() {
  ++counters_.syncs;
  if (nmt_ != NmtState::kOperational) return;
  const std::uint32_t cobId = get(od::kTpdo1Comm, 1);
  const std::uint32_t type = get(od::kTpdo1Comm, 2);
  if ((cobId & kPdoInvalid) || type == 0 || type > 240) return;
  if (++syncCount_ < static_cast<int>(type)) return;
  syncCount_ = 0;
  updateLiveObjects();
  CanFrame f = CanFrame::make(cobId & 0x7FF, {});
  std::size_t at = 0;
  const std::uint32_t entries = get(od::kTpdo1Map, 0);
  for (std::uint8_t s = 1; s <= entries && s <= 8; ++s) {
    const std::uint32_t m = get(od::kTpdo1Map, s);
    const int bytes = static_cast<int>((m & 0xFF) / 8);
    if (at + static_cast<std::size_t>(bytes) > 8) break;
    writeLe(f.data, at, get(static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>(m >> 8)), bytes);
    at += static_cast<std::size_t>(bytes);
  }
  f.len = static_cast<std::uint8_t>(at);
  send(f);
  ++counters_.tpdos;
}

void MotorSimulator::handleSdo(const CanFrame& f) {
  if (nmt_ == NmtState::kStopped || f.len < 8) return;  // no SDO in stopped state
  ++counters_.sdoRequests;
  const std::uint32_t txId = cob::kSdoTx + static_cast<std::uint32_t>(options_.node);
  const std::uint8_t cmd = f.data[0];
  const auto index = static_cast<std::uint16_t>(readLe(f.data, 1, 2));
  const std::uint8_t sub = f.data[3];
  auto abortWith = [&](std::uint32_t code) {
    ++counters_.sdoAborts;
    segmenting_ = false;
    send(sdoAbortFrame(txId, index, sub, code));
  };
  const int ccs = cmd >> 5;
  if (ccs == 4) {  // abort from the client
    segmenting_ = false;
    return;
  }
  if (abortsLeft_ > 0) {
    --abortsLeft_;
    abortWith(abortCode_);
    return;
  }
  if (ccs == 3) {  // upload segment request
    if (!segmenting_) return abortWith(abortcode::kBadCommand);
    if (((cmd >> 4) & 1) != static_cast<int>(segmentToggle_)) return abortWith(abortcode::kToggleBit);
    const std::size_t n = std::min<std::size_t>(7, segmentData_.size() - segmentOffset_);
    const bool last = segmentOffset_ + n >= segmentData_.size();
    CanFrame r = CanFrame::make(txId, {0, 0, 0, 0, 0, 0, 0, 0});
    r.data[0] = static_cast<std::uint8_t>((segmentToggle_ ? 0x10 : 0) | ((7 - n) << 1) | (last ? 1 : 0));
    for (std::size_t i = 0; i < n; ++i) r.data[1 + i] = static_cast<std::uint8_t>(segmentData_[segmentOffset_ + i]);
    segmentOffset_ += n;
    segmentToggle_ = !segmentToggle_;
    if (last) segmenting_ = false;
    send(r);
    return;
  }
  if (ccs == 2) {  // initiate upload
    if (index == od::kDeviceName && sub == 0) {
      segmenting_ = true;
      segmentData_ = options_.deviceName;
      segmentOffset_ = 0;
      segmentToggle_ = false;
      segmentIndex_ = index;
      CanFrame r = CanFrame::make(txId, {sdo::kUploadSegmentedStart, 0, 0, sub, 0, 0, 0, 0});
      writeLe(r.data, 1, index, 2);
      writeLe(r.data, 4, static_cast<std::uint32_t>(segmentData_.size()), 4);
      send(r);
      return;
    }
    auto it = od_.find(key(index, sub));
    if (it == od_.end()) {
      bool objectExists = std::any_of(od_.begin(), od_.end(), [&](const auto& e) { return (e.first >> 8) == index; });
      return abortWith(objectExists ? abortcode::kNoSubindex : abortcode::kNoObject);
    }
    updateLiveObjects();
    CanFrame r = CanFrame::make(txId, {sdo::uploadExpeditedResponse(it->second.size), 0, 0, sub, 0, 0, 0, 0});
    writeLe(r.data, 1, index, 2);
    writeLe(r.data, 4, it->second.value, it->second.size);
    send(r);
    return;
  }
  if (ccs == 1) {  // initiate download
    if (!(cmd & 0x02)) return abortWith(abortcode::kUnsupportedAccess);  // segmented download: not supported
    const int bytes = (cmd & 0x01) ? 4 - ((cmd >> 2) & 0x03) : 4;
    if (std::uint32_t code = write(index, sub, readLe(f.data, 4, bytes), bytes); code != 0) return abortWith(code);
    CanFrame r = CanFrame::make(txId, {sdo::kDownloadResponse, 0, 0, sub, 0, 0, 0, 0});
    writeLe(r.data, 1, index, 2);
    send(r);
    return;
  }
  abortWith(abortcode::kBadCommand);
}

std::uint32_t MotorSimulator::write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, int bytes) {
  if (index == od::kDeviceName) return abortcode::kReadOnly;
  auto it = od_.find(key(index, sub));
  if (it == od_.end()) {
    bool objectExists = std::any_of(od_.begin(), od_.end(), [&](const auto& e) { return (e.first >> 8) == index; });
    return objectExists ? abortcode::kNoSubindex : abortcode::kNoObject;
  }
  Entry& e = it->second;
  if (!e.writable) return abortcode::kReadOnly;
  if (bytes != e.size) return abortcode::kLengthMismatch;
  if (index == od::kTpdo1Comm && sub == 1) {
    // Only the valid bit may change while the PDO is valid (CiA 301).
    if (!(e.value & kPdoInvalid) && !(value & kPdoInvalid) && value != e.value) return abortcode::kValueRange;
    if ((value & 0x7FF) != (value & 0x1FFFFFFF) && !(value & 0x20000000)) return abortcode::kValueRange;
  }
  if (index == od::kTpdo1Map) {
    if (!(get(od::kTpdo1Comm, 1) & kPdoInvalid)) return abortcode::kDeviceState;
    if (sub == 0) {
      if (value > 8) return abortcode::kValueRange;
      std::uint32_t bits = 0;
      for (std::uint8_t s = 1; s <= value; ++s) bits += get(od::kTpdo1Map, s) & 0xFF;
      if (bits > 64) return 0x06040042;
    } else {
      if (get(od::kTpdo1Map, 0) != 0) return abortcode::kDeviceState;
      auto target = od_.find(key(static_cast<std::uint16_t>(value >> 16), static_cast<std::uint8_t>(value >> 8)));
      if (value != 0 && (target == od_.end() || !target->second.mappable)) return abortcode::kNotMappable;
      if (value != 0 && (value & 0xFF) != target->second.size * 8u) return abortcode::kLengthMismatch;
    }
  }
  if (index == od::kModeOfOperation && asInt(value << 24) >> 24 != od::kProfilePositionMode && value != 0)
    return abortcode::kValueRange;  // only profile position mode is simulated
  if ((index == od::kProfileVelocity || index == od::kProfileAcceleration || index == od::kProfileDeceleration) && value == 0)
    return abortcode::kValueRange;
  e.value = value;
  if (index == od::kControlword) applyControlword(static_cast<std::uint16_t>(value));
  if (index == od::kModeOfOperation) set(od::kModeDisplay, 0, value);
  return 0;
}

void MotorSimulator::applyControlword(std::uint16_t cw) {
  const std::uint16_t previous = controlword_;
  controlword_ = cw;
  const bool faultResetEdge = (cw & cw::kFaultReset) && !(previous & cw::kFaultReset);
  if (drive_ == DriveState::kFault) {
    if (faultResetEdge) {
      drive_ = DriveState::kSwitchOnDisabled;
      followingError_ = false;
      stalled_ = false;
      emcyActive_ = false;
      set(od::kErrorCode, 0, 0);
      set(od::kErrorRegister, 0, 0);
      send(emcyFrame(options_.node, Emcy{}));  // error reset
      ++counters_.emcys;
    }
    return;
  }
  if (drive_ == DriveState::kFaultReactionActive || drive_ == DriveState::kNotReadyToSwitchOn) return;
  const bool disableVoltage = (cw & 0x02) == 0;
  const bool quickStop = (cw & 0x06) == 0x02;
  const bool shutdown = (cw & 0x87) == 0x06;
  const bool switchOn = (cw & 0x8F) == 0x07;
  const bool enable = (cw & 0x8F) == 0x0F;
  switch (drive_) {
    case DriveState::kSwitchOnDisabled:
      if (shutdown) drive_ = DriveState::kReadyToSwitchOn;
      break;
    case DriveState::kReadyToSwitchOn:
      if (disableVoltage || quickStop) drive_ = DriveState::kSwitchOnDisabled;
      else if (switchOn) drive_ = DriveState::kSwitchedOn;
      else if (enable) drive_ = DriveState::kOperationEnabled;
      break;
    case DriveState::kSwitchedOn:
      if (disableVoltage || quickStop) drive_ = DriveState::kSwitchOnDisabled;
      else if (shutdown) drive_ = DriveState::kReadyToSwitchOn;
      else if (enable) drive_ = DriveState::kOperationEnabled;
      break;
    case DriveState::kOperationEnabled:
      if (disableVoltage) drive_ = DriveState::kSwitchOnDisabled;
      else if (quickStop) drive_ = DriveState::kQuickStopActive;
      else if (shutdown) drive_ = DriveState::kReadyToSwitchOn;
      else if (switchOn) drive_ = DriveState::kSwitchedOn;
      break;
    case DriveState::kQuickStopActive:
      if (disableVoltage) drive_ = DriveState::kSwitchOnDisabled;
      break;
    default:
      break;
  }
  if (drive_ != DriveState::kOperationEnabled) {
    profile_.stop();
    setPointAck_ = false;
    return;
  }
  halted_ = (cw & cw::kHalt) != 0;
  if (halted_) profile_.stop();
  const bool newSetPoint = (cw & cw::kNewSetPoint) && !(previous & cw::kNewSetPoint);
  if (newSetPoint && !halted_ && asInt(get(od::kModeDisplay, 0) << 24) >> 24 == od::kProfilePositionMode) {
    profile_.resume();
    profile_.setTarget(static_cast<double>(asInt(get(od::kTargetPosition, 0))));
    setPointAck_ = true;
    ++counters_.setPoints;
  }
  if (!(cw & cw::kNewSetPoint)) setPointAck_ = false;
}

void MotorSimulator::enterFault(std::uint16_t code, std::uint8_t errorRegister) {
  drive_ = DriveState::kFault;
  profile_.stop();
  setPointAck_ = false;
  set(od::kErrorCode, 0, code);
  set(od::kErrorRegister, 0, errorRegister);
  ++counters_.faults;
  Emcy e;
  e.code = code;
  e.errorRegister = errorRegister;
  send(emcyFrame(options_.node, e));
  ++counters_.emcys;
}

std::uint16_t MotorSimulator::computeStatusword() const {
  std::uint16_t s = 0;
  switch (drive_) {
    case DriveState::kNotReadyToSwitchOn: s = 0x0000; break;
    case DriveState::kSwitchOnDisabled: s = 0x0040; break;
    case DriveState::kReadyToSwitchOn: s = 0x0031; break;
    case DriveState::kSwitchedOn: s = 0x0033; break;
    case DriveState::kOperationEnabled: s = 0x0037; break;
    case DriveState::kQuickStopActive: s = 0x0017; break;
    case DriveState::kFaultReactionActive: s = 0x000F; break;
    case DriveState::kFault: s = 0x0008; break;
    case DriveState::kUnknown: break;
  }
  s |= 1u << 9;  // remote: controlled over the network
  if (emcyActive_ || followingError_) s |= sw::kWarning;
  if (profile_.reached() && std::abs(actual_ - profile_.target()) < 1.0) s |= sw::kTargetReached;
  if (setPointAck_) s |= sw::kSetPointAck;
  if (followingError_) s |= sw::kFollowingError;
  return s;
}

void MotorSimulator::updateLiveObjects() {
  set(od::kStatusword, 0, computeStatusword());
  set(od::kPositionActual, 0, static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(actual_))));
  set(od::kVelocityActual, 0, static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(actualVelocity_))));
}

void MotorSimulator::step(double dt) {
  if (drive_ == DriveState::kNotReadyToSwitchOn) drive_ = DriveState::kSwitchOnDisabled;  // self test passed
  const double vmax = std::min(get(od::kProfileVelocity, 0), get(od::kMaxProfileVelocity, 0));
  const double accel = std::min(get(od::kProfileAcceleration, 0), options_.maxAcceleration);
  const double decel = std::min(get(od::kProfileDeceleration, 0), options_.maxAcceleration);
  profile_.step(dt, std::max(1.0, vmax), std::max(1.0, accel), std::max(1.0, decel));
  if (drive_ == DriveState::kQuickStopActive && profile_.velocity() == 0.0) drive_ = DriveState::kSwitchOnDisabled;
  const double before = actual_;
  if (!stalled_) actual_ = profile_.position();
  actualVelocity_ = (actual_ - before) / dt;
  if (stalled_ && drive_ == DriveState::kOperationEnabled &&
      std::abs(profile_.position() - actual_) > static_cast<double>(get(od::kFollowingErrorWindow, 0))) {
    followingError_ = true;
    enterFault(0x8611, 0x21);  // following error; register: generic + device profile
    profile_.reset(actual_);   // the demand stays where the motor is
  }
  if (drive_ == DriveState::kFault) profile_.reset(actual_);
}

void MotorSimulator::poll(Stamp now) {
  std::lock_guard lock(mutex_);
  now_ = now;
  if (!started_) {
    started_ = true;
    last_ = now;
    boot(true);
  }
  runSchedule(now);
  // Injected faults.
  if (pendingPowerCycle_) {
    pendingPowerCycle_ = false;
    silent_ = stalled_ = inBusOff_ = false;
    boot(true);
  }
  if (pendingSilence_.count() > 0) {
    silent_ = true;
    silentUntil_ = now + std::chrono::nanoseconds(pendingSilence_).count();
    pendingSilence_ = {};
  }
  if (silent_ && now >= silentUntil_) silent_ = false;
  if (pendingBusOff_.count() > 0) {
    inBusOff_ = true;
    busOffUntil_ = now + std::chrono::nanoseconds(pendingBusOff_).count();
    pendingBusOff_ = {};
  }
  if (inBusOff_ && now >= busOffUntil_) {
    // The controller recovered (128 x 11 recessive bits): report it, restart communication.
    inBusOff_ = false;
    Emcy e;
    e.code = 0x8140;
    e.errorRegister = 0x11;  // generic + communication
    send(emcyFrame(options_.node, e));
    ++counters_.emcys;
    if (drive_ == DriveState::kOperationEnabled) drive_ = DriveState::kSwitchOnDisabled;  // lost its master
    profile_.stop();
    boot(false);
  }
  if (pendingStall_.count() > 0) {
    stalled_ = true;
    stalledUntil_ = now + std::chrono::nanoseconds(pendingStall_).count();
    pendingStall_ = {};
  }
  if (stalled_ && now >= stalledUntil_) stalled_ = false;
  if (pendingEmcy_ != 0) {
    emcyActive_ = true;
    enterFault(pendingEmcy_, 0x01);
    pendingEmcy_ = 0;
  }

  const double dt = static_cast<double>(now - last_) * 1e-9;
  last_ = now;
  if (booting_) {
    if (now < bootAt_) return;
    booting_ = false;
    ++counters_.boots;
    if (bootWhole_) {
      loadDeviceDefaults();
      drive_ = DriveState::kNotReadyToSwitchOn;
      controlword_ = 0;
      followingError_ = false;
      setPointAck_ = false;
      profile_.reset(actual_);
    }
    loadCommunicationDefaults();
    syncCount_ = 0;
    nmt_ = NmtState::kPreOperational;
    send(heartbeatFrame(options_.node, NmtState::kBootUp));
    ++counters_.heartbeats;
    nextHeartbeat_ = now + std::int64_t{get(od::kHeartbeatProducer, 0)} * 1'000'000;
  }
  step(std::min(dt, 0.1));  // a long pause (stopped process) is not one giant leap
  const std::int64_t hbNs = std::int64_t{get(od::kHeartbeatProducer, 0)} * 1'000'000;
  if (hbNs > 0 && now >= nextHeartbeat_) {
    send(heartbeatFrame(options_.node, nmt_));
    ++counters_.heartbeats;
    nextHeartbeat_ = nextHeartbeat_ + hbNs;
    if (nextHeartbeat_ <= now) nextHeartbeat_ = now + hbNs;  // late (or just enabled): restart the period
  }
}

void MotorSimulator::setSchedule(const FaultSchedule& schedule) {
  std::lock_guard lock(mutex_);
  schedule_ = schedule;
  scheduleStarted_ = false;
}

void MotorSimulator::runSchedule(Stamp now) {
  auto period = [](double s) { return static_cast<std::int64_t>(s * 1e9); };
  if (!scheduleStarted_) {
    scheduleStarted_ = true;
    nextEmcy_ = now + period(schedule_.emcyEvery);
    nextSilence_ = now + period(schedule_.silenceEvery);
    nextStall_ = now + period(schedule_.stallEvery);
    nextAbort_ = now + period(schedule_.abortEvery);
    nextBusOff_ = now + period(schedule_.busOffEvery);
  }
  auto due = [&](double every, Stamp& next) {
    if (every <= 0 || now < next) return false;
    next = now + period(every);
    return true;
  };
  if (due(schedule_.emcyEvery, nextEmcy_)) pendingEmcy_ = schedule_.emcyCode;
  if (due(schedule_.silenceEvery, nextSilence_)) pendingSilence_ = schedule_.silenceFor;
  if (due(schedule_.stallEvery, nextStall_)) pendingStall_ = schedule_.stallFor;
  if (due(schedule_.abortEvery, nextAbort_)) {
    abortsLeft_ = 1;
    abortCode_ = abortcode::kGeneral;
  }
  if (due(schedule_.busOffEvery, nextBusOff_)) pendingBusOff_ = schedule_.busOffFor;
}

void MotorSimulator::injectEmcy(std::uint16_t code) {
  std::lock_guard lock(mutex_);
  pendingEmcy_ = code == 0 ? 0xFF00 : code;
}
void MotorSimulator::silence(std::chrono::milliseconds d) {
  std::lock_guard lock(mutex_);
  pendingSilence_ = d;
}
void MotorSimulator::stall(std::chrono::milliseconds d) {
  std::lock_guard lock(mutex_);
  pendingStall_ = d;
}
void MotorSimulator::abortSdo(int count, std::uint32_t code) {
  std::lock_guard lock(mutex_);
  abortsLeft_ = count;
  abortCode_ = code;
}
void MotorSimulator::busOff(std::chrono::milliseconds d) {
  std::lock_guard lock(mutex_);
  pendingBusOff_ = d;
}
void MotorSimulator::powerCycle() {
  std::lock_guard lock(mutex_);
  pendingPowerCycle_ = true;
}

NmtState MotorSimulator::nmtState() const {
  std::lock_guard lock(mutex_);
  return nmt_;
}
DriveState MotorSimulator::driveState() const {
  std::lock_guard lock(mutex_);
  return drive_;
}
std::uint16_t MotorSimulator::statusword() const {
  std::lock_guard lock(mutex_);
  return computeStatusword();
}
std::int32_t MotorSimulator::position() const {
  std::lock_guard lock(mutex_);
  return static_cast<std::int32_t>(std::lround(actual_));
}
double MotorSimulator::velocity() const {
  std::lock_guard lock(mutex_);
  return actualVelocity_;
}
MotorSimCounters MotorSimulator::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

}  // namespace fusedet::drivers::canopen::sim
