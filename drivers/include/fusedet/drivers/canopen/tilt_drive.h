// SPDX-License-Identifier: Apache-2.0
#pragma once
// TiltDrive: the CANopen master for the nodding tilt motor (one CiA 402 drive), as a CanNode.
// Bring-up: NMT reset node, wait for the boot-up message, check the device type (402), read the
// device name (segmented upload), configure by SDO (heartbeat producer, TPDO1 = position actual +
// statusword on every SYNC, profile position mode, velocity, acceleration, following-error
// window), NMT start, then walk the CiA 402 state machine to operation enabled (fault reset if
// needed). Then it nods between the configured angles (target position + new set-point,
// acknowledge handshake, target reached from the TPDO statusword) or holds an angle.
// It produces SYNC, consumes the heartbeat, decodes EMCY and emits one TiltSample per TPDO
// (stamped at reception). Faults - EMCY, drive fault or following error in the statusword,
// heartbeat loss, an unexpected boot-up, an SDO abort or timeout - stop the sweep (halt), are
// reported with their cause and recovered: reconfigure, fault reset, re-enable, resume
// (retries back off 100 ms doubling to 2 s; after heartbeat loss, as soon as the node is heard).
// Thread-safe; the sample and fault callbacks run under the drive's lock and must not call it.

#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>

#include "fusedet/drivers/canopen/can_node.h"
#include "fusedet/drivers/canopen/protocol.h"
#include "fusedet/drivers/canopen/sdo_client.h"
#include "fusedet/drivers/canopen/tilt_tpdo.h"
#include "fusedet/drivers/canopen/tilt_units.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::canopen {

struct TiltDriveConfig {
  int node = 5;                  // tilt.node_id
  double minDeg = -30.0;         // tilt.min_deg
  double maxDeg = 30.0;          // tilt.max_deg
  double speedDegS = 15.0;       // tilt.speed_deg_s
  TiltUnits units;               // tilt.counts_per_rev, gear_ratio, zero_offset_counts
  int heartbeatMs = 100;         // tilt.heartbeat_ms: written to 0x1017, loss after 3 periods
  // Driver constants (not config keys):
  double accelDegS2 = 60.0;      // profile acceleration and deceleration
  double followingErrorDeg = 1.0;
  std::chrono::milliseconds syncPeriod{10};   // one TiltSample per SYNC: 100 Hz
  std::chrono::milliseconds sdoTimeout{200};
  std::chrono::milliseconds bootTimeout{1000};
  double heartbeatLossPeriods = 3.0;
  std::chrono::milliseconds retryMin{100}, retryMax{2000};

  std::string validate() const;  // empty if usable
  // stop() ends by then, acknowledged or not (halt + shutdown, each an SDO of sdoTimeout).
  std::chrono::milliseconds stopTimeout() const { return sdoTimeout * 3; }
};

enum class TiltPhase { kIdle, kBooting, kConfiguring, kEnabling, kRunning, kFault, kStopping, kStopped };
std::string_view toString(TiltPhase p);

struct TiltDriveCounters {
  SdoCounters sdo;
  std::uint64_t syncs = 0;
  std::uint64_t samples = 0;        // TPDOs decoded into TiltSamples
  std::uint64_t badPdos = 0;        // TPDOs too short to decode
  std::uint64_t heartbeats = 0;
  std::uint64_t bootUps = 0;
  std::uint64_t emcys = 0;
  std::uint64_t errorFrames = 0;
  std::uint64_t faults = 0;
  std::uint64_t recoveries = 0;
  std::uint64_t moves = 0;          // targets reached
  std::uint64_t sweeps = 0;         // nods completed (one end to the other)
  double lastRecoverySeconds = 0;   // fault detected -> operation enabled again
  std::string lastFault;            // cause, e.g. "EMCY 0x8611 following error (...)"
  std::string deviceName;           // 0x1008
  std::uint16_t statusword = 0;
  std::uint16_t lastEmcyCode = 0;
  TiltPhase phase = TiltPhase::kIdle;
};

// What happened, for logs and command lines (one line each).
struct TiltEvent {
  enum class Kind { kOperationEnabled, kSweep, kFault, kRecovered } kind = Kind::kFault;
  double seconds = 0;         // kOperationEnabled: since start(); kRecovered: since the fault
  std::uint64_t index = 0;    // kSweep: sweep number (1, 2, ...)
  double minRad = 0, maxRad = 0;  // kSweep: extreme sampled angles of the sweep
  std::uint64_t samples = 0;  // kSweep: TiltSamples during the sweep
  std::string cause;          // kFault
};

class TiltDrive : public CanNode {
 public:
  using SampleHandler = std::function<void(const TiltSample&)>;
  using FaultHandler = std::function<void(const std::string& cause)>;
  using EventHandler = std::function<void(const TiltEvent&)>;

  TiltDrive(CanBus& bus, TiltDriveConfig config, SampleHandler onSample = {});
  void setFaultHandler(FaultHandler h);
  void setEventHandler(EventHandler h);

  // Bring the drive up (reset node first) and then nod; hold(angle) instead holds one angle.
  // Calling start() again restarts from scratch (after runNode() returned a bus failure: reopen
  // the same SocketCanBus object, start(), run again).
  void start();
  void nod();
  void hold(double angleRad);
  // Halt, shutdown (drive disabled), NMT pre-operational, SYNC off; stopped() once done, at the
  // latest after config().stopTimeout(). stopConfirmed(): the node acknowledged both the halt
  // and the shutdown (or the drive was never started) - false when stopped() came by timeout, so
  // the motor may still be moving.
  void stop();
  bool stopConfirmed() const;

  void onFrame(const CanFrame& f) override;
  void poll(Stamp now) override;

  TiltPhase phase() const;
  bool running() const { return phase() == TiltPhase::kRunning; }
  bool stopped() const { return phase() == TiltPhase::kStopped; }
  // True when nodding/holding and the current move has reached its target.
  bool idleAtTarget() const;
  TiltDriveCounters counters() const;
  const TiltDriveConfig& config() const { return config_; }
  // The angles (rad) the drive is commanded between.
  double minRad() const;
  double maxRad() const;

 private:
  enum class Motion { kNod, kHold };
  enum class MoveStep { kNone, kCommanding, kAwaitReached };

  // `reachable` = false when the node did not answer: then no halt is sent.
  void fault(const std::string& cause, bool reachable = true);
  void beginConfigure();
  void beginEnable();
  void enableStep();
  void beginMove();
  void awaitSetPointAck();
  void onSdoError(std::uint64_t generation, const Error& e);
  void handleHeartbeat(const CanFrame& f);
  void handleEmcy(const CanFrame& f);
  void handleTpdo(const CanFrame& f);
  void setFilters();
  std::function<void(Result<SdoClient::Bytes>)> expectOk(std::function<void(SdoClient::Bytes)> then = {});

  CanBus& bus_;
  TiltDriveConfig config_;
  SampleHandler onSample_;
  FaultHandler onFault_;
  mutable std::recursive_mutex mutex_;  // SDO callbacks re-enter the drive
  SdoClient sdo_;
  TiltTpdoDecoder tpdo_;  // TPDO1 -> TiltSample (shared with the log replay)
  TiltDriveCounters counters_;

  TiltPhase phase_ = TiltPhase::kIdle;
  bool haltAcked_ = false, stopConfirmed_ = false;
  bool startRequested_ = false;
  std::uint64_t generation_ = 0;   // bumped on every fault: stale SDO callbacks are ignored
  Stamp now_{};
  Stamp phaseDeadline_{};
  Stamp nextSync_{};
  bool heartbeatArmed_ = false;
  Stamp lastHeartbeat_{};
  bool heardSinceFault_ = false;
  bool heartbeatFault_ = false;
  Stamp faultAt_{};
  Stamp retryAt_{};
  std::chrono::milliseconds backoff_{0};
  int enableSteps_ = 0;
  bool recovering_ = false;

  Motion motion_ = Motion::kNod;
  double holdRad_ = 0;
  MoveStep move_ = MoveStep::kNone;
  std::int32_t moveTarget_ = 0;
  bool nextToMax_ = true;
  bool positioned_ = false;  // at one end: the next nod move is a full sweep
  int ackPolls_ = 0;

  EventHandler onEvent_;
  Stamp startedAt_{};
  bool everEnabled_ = false;
  double sweepMin_ = 0, sweepMax_ = 0;
  std::uint64_t sweepSamples_ = 0;
  void emit(const TiltEvent& e) {
    if (onEvent_) onEvent_(e);
  }
};

}  // namespace fusedet::drivers::canopen
