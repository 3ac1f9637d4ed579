// SPDX-License-Identifier: Apache-2.0
#pragma once
// runNodSimulation: the tilt drive and the motor simulator on an in-process bus with simulated
// time, nodding for a number of sweeps, all traffic written as a candump log (what
// `fusedet tilt simulate` runs; the sensor-log tools use it to synthesise CAN traffic).

#include <functional>
#include <string>

#include "fusedet/core/result.h"
#include "fusedet/drivers/canopen/tilt_drive.h"
#include "motor_simulator.h"

namespace fusedet::drivers::canopen::sim {

enum class FaultKind { kNone, kEmcy, kSilence, kStall, kSdoAbort, kBusOff };
Result<FaultKind> parseFaultKind(const std::string& name);  // none emcy silence stall sdo-abort bus-off
std::string_view toString(FaultKind k);

struct NodSimulationOptions {
  TiltDriveConfig drive;
  int sweeps = 2;
  std::string candumpPath;        // "" = no log
  std::string interface = "can0"; // written in the log lines
  double startSeconds = 1000.0;   // simulated CLOCK_MONOTONIC at the start
  FaultKind fault = FaultKind::kNone;
  double faultAtSeconds = 5.0;    // after the start
  double limitSeconds = 0;        // give up after this much simulated time (0 = from the sweeps)
  TiltDrive::EventHandler onEvent;  // start-up, sweeps, faults, recoveries
  // Every frame as it goes on the bus (either node's transmission), in bus order: what a
  // listening socket (candump, `fusedet record`) sees.
  std::function<void(const CanFrame&)> onFrame;
  // Once per simulated step (1 ms), after it: the motor's actual position [counts] (what an
  // encoder on the tilt axis reads; synth-log points its virtual laser with it) and the drive's
  // counters (moves = targets reached so far).
  std::function<void(Stamp now, std::int32_t motorCounts, const TiltDriveCounters& drive)> onStep;
};

struct NodSimulationReport {
  double seconds = 0;             // simulated time used
  std::uint64_t frames = 0;       // frames on the bus (= lines in the log)
  TiltDriveCounters drive;
  MotorSimCounters motor;
};

// Errors: log not writable, invalid drive config, sweeps not completed within the limit.
Result<NodSimulationReport> runNodSimulation(const NodSimulationOptions& o,
                                             const std::function<void(const TiltSample&)>& onSample = {});

}  // namespace fusedet::drivers::canopen::sim
