// SPDX-License-Identifier: Apache-2.0
#pragma once
// MotorSimulator: a CiA 402 servo drive with a CiA 301 CANopen interface, as one CanNode.
//  - NMT slave: boot-up message after power-on / reset, pre-operational, operational, stopped;
//    reset node restores the whole object dictionary, reset communication the 0x1000 area.
//  - Object dictionary (0x1000 device type 402, 0x1001, 0x1008 name (segmented upload), 0x1017,
//    0x1800/0x1A00 TPDO1, 0x603F, 0x6040/0x6041, 0x6060/0x6061, 0x6064, 0x6065, 0x606C, 0x607A,
//    0x607F, 0x6081, 0x6083, 0x6084) behind an SDO server (expedited download, expedited and
//    segmented upload, abort codes for unknown objects, read-only writes, bad sizes/values).
//  - Heartbeat producer (0x1017), TPDO1 on SYNC (transmission type 1..240, mapping from 0x1A00).
//  - CiA 402 power state machine driven by the controlword; profile position mode with the
//    new-set-point handshake (bit 4 -> statusword bit 12), target reached (bit 10); kinematics
//    with velocity (min of 0x6081, 0x607F) and acceleration/deceleration limits (0x6083/0x6084).
//  - Faults: EMCY (drive fault with a given error code), silence (neither sends nor hears),
//    stall (the motor stops following: following error once it exceeds 0x6065, EMCY 0x8611),
//    SDO aborts (the next n requests), bus-off (mute, then recovery: EMCY 0x8140 and reset
//    communication, so the master sees a boot-up). A fault reset clears injected faults.
// Thread-safe: the fault-injection calls may come from another thread than onFrame()/poll().

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>

#include "fusedet/drivers/canopen/can_node.h"
#include "fusedet/drivers/canopen/protocol.h"
#include "motion_profile.h"

namespace fusedet::drivers::canopen::sim {

struct MotorSimOptions {
  int node = 5;
  std::string deviceName = "fusedet tilt-sim CiA 402 drive";
  std::chrono::milliseconds bootTime{20};    // power-on / reset -> boot-up message
  std::uint16_t heartbeatMs = 0;             // 0x1017 default (0 = off until the master sets it)
  std::uint32_t maxVelocity = 2'000'000;     // 0x607F [counts/s], a hard limit
  std::uint32_t velocity = 100'000;          // 0x6081 default
  std::uint32_t acceleration = 500'000;      // 0x6083 / 0x6084 defaults [counts/s^2]
  std::uint32_t maxAcceleration = 5'000'000; // the motor cannot do more, whatever 0x6083 says
  std::uint32_t followingErrorWindow = 2000; // 0x6065 default [counts]
  std::int32_t initialPosition = 0;
};

// Faults repeated at fixed periods (tilt-sim's --*-every options); 0 = never.
struct FaultSchedule {
  double emcyEvery = 0;        // [s] drive fault with EMCY `emcyCode`
  std::uint16_t emcyCode = 0x2310;
  double silenceEvery = 0;
  std::chrono::milliseconds silenceFor{500};
  double stallEvery = 0;       // following error
  std::chrono::milliseconds stallFor{1000};
  double abortEvery = 0;       // the next SDO request is aborted (0x08000000)
  double busOffEvery = 0;
  std::chrono::milliseconds busOffFor{200};
};

struct MotorSimCounters {
  std::uint64_t framesIn = 0;
  std::uint64_t framesOut = 0;
  std::uint64_t sendFailures = 0;
  std::uint64_t sdoRequests = 0;
  std::uint64_t sdoAborts = 0;
  std::uint64_t syncs = 0;
  std::uint64_t tpdos = 0;
  std::uint64_t heartbeats = 0;
  std::uint64_t emcys = 0;
  std::uint64_t boots = 0;
  std::uint64_t faults = 0;
  std::uint64_t setPoints = 0;    // new set-points accepted
};

class MotorSimulator : public CanNode {
 public:
  MotorSimulator(CanBus& bus, MotorSimOptions options);

  void onFrame(const CanFrame& f) override;
  void poll(Stamp now) override;

  // Fault injection (takes effect at the next poll).
  void injectEmcy(std::uint16_t code);                // drive fault with this error code
  void silence(std::chrono::milliseconds duration);   // the node is cut off the bus
  void stall(std::chrono::milliseconds duration);     // motor blocked -> following error
  void abortSdo(int count, std::uint32_t code = abortcode::kGeneral);
  void busOff(std::chrono::milliseconds duration);
  void powerCycle();                                  // as if the supply were switched off and on
  void setSchedule(const FaultSchedule& schedule);    // periods count from the next poll

  NmtState nmtState() const;
  DriveState driveState() const;
  std::uint16_t statusword() const;
  std::int32_t position() const;     // actual position [counts]
  double velocity() const;           // [counts/s]
  MotorSimCounters counters() const;

 private:
  struct Entry {
    std::uint32_t value = 0;
    std::uint8_t size = 4;  // bytes
    bool writable = false;
    bool mappable = false;
  };
  static std::uint32_t key(std::uint16_t index, std::uint8_t sub) { return std::uint32_t{index} << 8 | sub; }

  void boot(bool wholeDictionary);
  void loadCommunicationDefaults();
  void loadDeviceDefaults();
  void send(const CanFrame& f);
  void handleNmt(const CanFrame& f);
  void handleSdo(const CanFrame& f);
  void handleSync();
  // SDO write of one object; 0 = accepted, else the abort code.
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, int bytes);
  void applyControlword(std::uint16_t cw);
  void enterFault(std::uint16_t code, std::uint8_t errorRegister);
  void updateLiveObjects();
  void step(double dt);
  std::uint16_t computeStatusword() const;
  std::uint32_t get(std::uint16_t index, std::uint8_t sub) const;
  void set(std::uint16_t index, std::uint8_t sub, std::uint32_t v);

  CanBus& bus_;
  MotorSimOptions options_;
  mutable std::mutex mutex_;
  std::map<std::uint32_t, Entry> od_;
  MotorSimCounters counters_;

  NmtState nmt_ = NmtState::kBootUp;
  bool booting_ = true;
  bool bootWhole_ = true;
  Stamp bootAt_{};
  bool started_ = false;  // first poll seen
  Stamp last_{};
  Stamp nextHeartbeat_{};
  int syncCount_ = 0;

  DriveState drive_ = DriveState::kNotReadyToSwitchOn;
  std::uint16_t controlword_ = 0;
  bool setPointAck_ = false;
  bool followingError_ = false;
  bool halted_ = false;
  MotionProfile profile_;       // demand trajectory
  double actual_ = 0;           // actual position (= demand unless stalled)
  double actualVelocity_ = 0;

  // Segmented upload in progress.
  bool segmenting_ = false;
  std::string segmentData_;
  std::size_t segmentOffset_ = 0;
  bool segmentToggle_ = false;
  std::uint16_t segmentIndex_ = 0;

  // Injected faults (applied in poll()).
  std::uint16_t pendingEmcy_ = 0;
  bool emcyActive_ = false;
  std::chrono::milliseconds pendingSilence_{0}, pendingStall_{0}, pendingBusOff_{0};
  bool pendingPowerCycle_ = false;
  Stamp silentUntil_{}, stalledUntil_{}, busOffUntil_{};
  bool silent_ = false, stalled_ = false, inBusOff_ = false;
  int abortsLeft_ = 0;
  std::uint32_t abortCode_ = 0;
  Stamp now_{};
  FaultSchedule schedule_;
  bool scheduleStarted_ = false;
  Stamp nextEmcy_{}, nextSilence_{}, nextStall_{}, nextAbort_{}, nextBusOff_{};
  void runSchedule(Stamp now);
};

}  // namespace fusedet::drivers::canopen::sim
