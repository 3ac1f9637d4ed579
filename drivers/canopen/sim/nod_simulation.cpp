// SPDX-License-Identifier: Apache-2.0
#include "nod_simulation.h"

#include <chrono>

#include "fusedet/drivers/canopen/candump_log.h"
#include "fusedet/drivers/canopen/simulated_network.h"

namespace fusedet::drivers::canopen::sim {

Result<FaultKind> parseFaultKind(const std::string& name) {
  if (name == "none") return FaultKind::kNone;
  if (name == "emcy") return FaultKind::kEmcy;
  if (name == "silence") return FaultKind::kSilence;
  if (name == "stall") return FaultKind::kStall;
  if (name == "sdo-abort") return FaultKind::kSdoAbort;
  if (name == "bus-off") return FaultKind::kBusOff;
  return makeError(std::errc::invalid_argument, "unknown fault '" + name + "' (none emcy silence stall sdo-abort bus-off)");
}

std::string_view toString(FaultKind k) {
  switch (k) {
    case FaultKind::kNone: return "none";
    case FaultKind::kEmcy: return "emcy";
    case FaultKind::kSilence: return "silence";
    case FaultKind::kStall: return "stall";
    case FaultKind::kSdoAbort: return "sdo-abort";
    case FaultKind::kBusOff: return "bus-off";
  }
  return "unknown";
}

Result<NodSimulationReport> runNodSimulation(const NodSimulationOptions& o,
                                             const std::function<void(const TiltSample&)>& onSample) {
  if (const std::string why = o.drive.validate(); !why.empty()) return makeError(std::errc::invalid_argument, why);
  if (o.sweeps < 0) return makeError(std::errc::invalid_argument, "sweeps must not be negative");
  SimulatedNetwork net(o.interface, Stamp::fromSeconds(o.startSeconds));
  CandumpWriter log;
  if (!o.candumpPath.empty())
    if (auto r = log.open(o.candumpPath, o.interface); !r) return r.error();
  InProcessBus::Endpoint& masterBus = net.connect();
  InProcessBus::Endpoint& motorBus = net.connect();
  // The log takes every frame either node sends, in the order they went on the bus.
  std::uint64_t frames = 0;
  auto onBus = [&](const CanFrame& f, FrameDirection d) {
    if (d != FrameDirection::kTx) return;
    ++frames;
    log.write(f);  // no-op without a log file
    if (o.onFrame) o.onFrame(f);
  };
  masterBus.setFrameHook(onBus);
  motorBus.setFrameHook(onBus);
  MotorSimOptions mo;
  mo.node = o.drive.node;
  MotorSimulator motor(motorBus, mo);
  TiltDrive drive(masterBus, o.drive, onSample);
  if (o.onEvent) drive.setEventHandler(o.onEvent);
  net.attach(motor, motorBus);
  net.attach(drive, masterBus);
  const Stamp start = net.now();
  drive.start();
  const double sweepS = (o.drive.maxDeg - o.drive.minDeg) / o.drive.speedDegS + o.drive.speedDegS / o.drive.accelDegS2;
  const double limit = o.limitSeconds > 0 ? o.limitSeconds : 10.0 + (o.sweeps + 2) * sweepS * 2.0;
  bool injected = o.fault == FaultKind::kNone;
  auto inject = [&] {
    switch (o.fault) {
      case FaultKind::kEmcy: motor.injectEmcy(0x2310); break;
      case FaultKind::kSilence: motor.silence(std::chrono::milliseconds(800)); break;
      case FaultKind::kStall: motor.stall(std::chrono::milliseconds(1000)); break;
      case FaultKind::kSdoAbort: motor.abortSdo(1, abortcode::kGeneral); break;
      case FaultKind::kBusOff: motor.busOff(std::chrono::milliseconds(200)); break;
      case FaultKind::kNone: break;
    }
  };
  const bool done = net.runUntil(
      [&] {
        if (o.onStep) o.onStep(net.now(), motor.position(), drive.counters());
        if (!injected && net.now() - start >= static_cast<std::int64_t>(o.faultAtSeconds * 1e9)) {
          injected = true;
          inject();
        }
        return drive.counters().sweeps >= static_cast<std::uint64_t>(o.sweeps) && (injected || o.sweeps == 0);
      },
      std::chrono::nanoseconds(static_cast<std::int64_t>(limit * 1e9)));
  drive.stop();
  auto stepped = [&] {
    if (o.onStep) o.onStep(net.now(), motor.position(), drive.counters());
  };
  (void)net.runUntil(
      [&] {
        stepped();
        return drive.stopped();
      },
      std::chrono::seconds(2));
  (void)net.runUntil(  // deliver what is still in flight
      [&, end = net.now() + std::int64_t{20'000'000}] {
        stepped();
        return net.now() >= end;
      },
      std::chrono::seconds(1));
  NodSimulationReport report;
  report.seconds = static_cast<double>(net.now() - start) * 1e-9;
  report.frames = frames;
  report.drive = drive.counters();
  report.motor = motor.counters();
  if (auto r = log.close(); !r) return r.error();
  if (!done)
    return makeError(std::errc::timed_out, "only " + std::to_string(report.drive.sweeps) + " of " +
                                               std::to_string(o.sweeps) + " sweeps in " + std::to_string(limit) +
                                               " s of simulated time (last fault: " + report.drive.lastFault + ")");
  return report;
}

}  // namespace fusedet::drivers::canopen::sim
