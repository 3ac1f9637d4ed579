// SPDX-License-Identifier: Apache-2.0
// fusedet tilt: the CANopen CiA 402 tilt motor (or tilt-sim) on SocketCAN, and its simulation.
//   status    one look at the drive over SDO (changes nothing)
//   nod       bring the drive up and nod between the configured angles
//   home      bring the drive up and hold an angle (default 0), then leave it holding
//   monitor   print every CAN frame with its CANopen meaning
//   simulate  drive + simulator on an in-process bus (simulated time), traffic as a candump log

#include <atomic>
#include <csignal>
#include <cstdio>
#include <numbers>
#include <thread>

#include "command.h"
#include "fusedet/daemon/config.h"
#include "fusedet/drivers/canopen/candump_log.h"
#include "fusedet/drivers/canopen/drive_status.h"
#include "fusedet/drivers/canopen/frame_text.h"
#include "fusedet/drivers/canopen/socketcan_bus.h"
#include "fusedet/drivers/canopen/tilt_drive.h"
#include "nod_simulation.h"

namespace fusedet::tools {
namespace {

using namespace drivers::canopen;
constexpr double kDeg = std::numbers::pi / 180.0;

std::atomic<bool> gInterrupted{false};
extern "C" void onTiltSignal(int) { gInterrupted = true; }

struct TiltOptions {
  std::string can;
  int node = 0;  // 0 = from the config
  std::string config;
  double minDeg = NAN, maxDeg = NAN, speedDegS = NAN;
  int sweeps = 0;
  double duration = 0;
  double angleDeg = 0;
  long count = 0;
  bool samples = false;
  bool json = false;
  std::string candump;
  std::string fault = "none";
  double faultAt = 5.0;
  std::string interface = "can0";
  int sdoTimeoutMs = 200;
  int heartbeatMs = 0;  // 0 = from the config
};

TiltDriveConfig driveConfig(const TiltOptions& o, std::string* iface = nullptr) {
  daemon::Config file;
  if (!o.config.empty()) file = daemon::loadConfig(o.config);
  const auto& t = file.tilt;
  TiltDriveConfig c;
  c.node = o.node > 0 ? o.node : t.nodeId;
  c.minDeg = std::isnan(o.minDeg) ? t.minDeg : o.minDeg;
  c.maxDeg = std::isnan(o.maxDeg) ? t.maxDeg : o.maxDeg;
  c.speedDegS = std::isnan(o.speedDegS) ? t.speedDegS : o.speedDegS;
  c.units.countsPerRev = t.countsPerRev;
  c.units.gearRatio = t.gearRatio;
  c.units.zeroOffsetCounts = static_cast<std::int32_t>(t.zeroOffsetCounts);
  c.heartbeatMs = o.heartbeatMs > 0 ? o.heartbeatMs : t.heartbeatMs;
  c.sdoTimeout = std::chrono::milliseconds(o.sdoTimeoutMs);
  if (const std::string why = c.validate(); !why.empty()) throw std::runtime_error(why);
  if (iface) *iface = o.can.empty() ? t.interface : o.can;
  return c;
}

std::string jsonEscape(const std::string& in) {
  std::string out;
  for (char c : in) {
    if (c == '"' || c == '\\') out += '\\';
    out += (static_cast<unsigned char>(c) < 0x20) ? ' ' : c;
  }
  return out;
}

void openBus(SocketCanBus& bus, const std::string& iface) {
  if (auto r = bus.open(iface); !r) throw std::runtime_error(r.error().message());
}

void printSample(const drivers::TiltSample& s, bool json) {
  if (json)
    std::printf("{\"stamp\":%s,\"angle_deg\":%.5f,\"velocity_deg_s\":%.4f}\n", s.stamp.toString().c_str(), s.angle / kDeg,
                s.velocity / kDeg);
  else
    std::printf("%s %9.4f deg %8.3f deg/s\n", s.stamp.toString().c_str(), s.angle / kDeg, s.velocity / kDeg);
}

// One greppable line per drive event, on stdout (samples, if asked for, are interleaved).
void printEvent(const TiltEvent& e) {
  switch (e.kind) {
    case TiltEvent::Kind::kOperationEnabled:
      std::printf("tilt: operation enabled after %.0f ms\n", e.seconds * 1e3);
      break;
    case TiltEvent::Kind::kSweep:
      std::printf("tilt: sweep %llu from %.3f to %.3f deg, %llu samples\n", (unsigned long long)e.index, e.minRad / kDeg,
                  e.maxRad / kDeg, (unsigned long long)e.samples);
      break;
    case TiltEvent::Kind::kFault:
      std::printf("tilt: fault: %s\n", e.cause.c_str());
      break;
    case TiltEvent::Kind::kRecovered:
      std::printf("tilt: recovered in %.0f ms\n", e.seconds * 1e3);
      break;
  }
  std::fflush(stdout);
}

void printCounters(const TiltDriveCounters& c) {
  std::fprintf(stderr,
               "tilt: phase %s, sweeps %llu, moves %llu, samples %llu, SYNC %llu, heartbeats %llu, boot-ups %llu, "
               "EMCY %llu, faults %llu, recoveries %llu (last %.3f s), SDO ok %llu aborts %llu timeouts %llu%s%s\n",
               std::string(toString(c.phase)).c_str(), (unsigned long long)c.sweeps, (unsigned long long)c.moves,
               (unsigned long long)c.samples, (unsigned long long)c.syncs, (unsigned long long)c.heartbeats,
               (unsigned long long)c.bootUps, (unsigned long long)c.emcys, (unsigned long long)c.faults,
               (unsigned long long)c.recoveries, c.lastRecoverySeconds, (unsigned long long)c.sdo.transfers,
               (unsigned long long)c.sdo.aborts, (unsigned long long)c.sdo.timeouts,
               c.lastFault.empty() ? "" : ", last fault: ", c.lastFault.c_str());
}

int runStatus(const TiltOptions& o) {
  std::string iface;
  const TiltDriveConfig c = driveConfig(o, &iface);
  SocketCanBus bus;
  openBus(bus, iface);
  auto r = queryDriveStatus(bus, c.node);
  if (!r) throw std::runtime_error(r.error().message());
  std::printf("interface   %s\nnode        %d\ndevice type 0x%08X%s\nname        %s\nnmt         %s\n", iface.c_str(),
              c.node, r->deviceType, (r->deviceType & 0xFFFF) == 402 ? " (CiA 402 drive)" : " (not CiA 402)",
              r->deviceName.c_str(), r->nmt ? std::string(toString(*r->nmt)).c_str() : "no heartbeat heard");
  std::printf("statusword  0x%04X (%s%s%s)\nmode        %d%s\nposition    %d counts = %.4f deg\nerror code  %s\n"
              "heartbeat   %u ms\n",
              r->statusword, std::string(toString(r->state)).c_str(), (r->statusword & sw::kTargetReached) ? ", target reached" : "",
              (r->statusword & sw::kFollowingError) ? ", following error" : "", r->mode,
              r->mode == od::kProfilePositionMode ? " (profile position)" : "", r->position,
              c.units.toRad(r->position) / kDeg, emcyCodeText(r->errorCode).c_str(), r->heartbeatMs);
  return 0;
}

// Runs the drive on the socket until `done` (or Ctrl-C / --duration), then `finish`es it.
int runDrive(const TiltOptions& o, const std::function<void(TiltDrive&)>& begin,
             const std::function<bool(const TiltDrive&)>& done, bool stopAtEnd) {
  std::string iface;
  const TiltDriveConfig c = driveConfig(o, &iface);
  SocketCanBus bus;
  openBus(bus, iface);
  CandumpWriter log;
  if (!o.candump.empty()) {
    if (auto r = log.open(o.candump, iface); !r) throw std::runtime_error(r.error().message());
    bus.setFrameHook([&](const CanFrame& f, FrameDirection) { log.write(f); });
  }
  TiltDrive drive(bus, c, [&](const drivers::TiltSample& s) {
    if (o.samples || o.json) printSample(s, o.json);
  });
  drive.setEventHandler([](const TiltEvent& e) { printEvent(e); });
  std::signal(SIGINT, onTiltSignal);
  std::signal(SIGTERM, onTiltSignal);
  std::atomic<bool> stopRunner{false};
  Result<void> runResult;
  begin(drive);
  drive.start();
  std::atomic<bool> runnerEnded{false};  // the bus failed (interface gone or down)
  std::thread runner([&] {
    runResult = runNode(bus, drive, stopRunner);
    runnerEnded = true;
  });
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  while (!gInterrupted && !runnerEnded && !done(drive) && (o.duration <= 0 || elapsed() < o.duration))
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (stopAtEnd) {
    drive.stop();
    for (int i = 0; i < 300 && !drive.stopped() && !runnerEnded; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stopRunner = true;
  runner.join();
  std::fflush(stdout);
  printCounters(drive.counters());
  if (auto r = log.close(); !r) throw std::runtime_error(r.error().message());
  if (!runResult) throw std::runtime_error(runResult.error().message());
  return 0;
}

int runNod(const TiltOptions& o) {
  const auto sweeps = static_cast<std::uint64_t>(o.sweeps);
  return runDrive(o, [](TiltDrive& d) { d.nod(); },
                  [sweeps](const TiltDrive& d) { return sweeps > 0 && d.counters().sweeps >= sweeps; }, true);
}

int runHome(const TiltOptions& o) {
  const double angle = o.angleDeg * kDeg;
  int rc = runDrive(o, [angle](TiltDrive& d) { d.hold(angle); },
                    [](const TiltDrive& d) { return d.idleAtTarget() && d.counters().moves >= 1; }, false);
  std::printf("holding at %.3f deg (drive left enabled)\n", o.angleDeg);
  return rc;
}

int runMonitor(const TiltOptions& o) {
  std::string iface;
  (void)driveConfig(o, &iface);
  SocketCanBus bus;
  openBus(bus, iface);
  CandumpWriter log;
  if (!o.candump.empty())
    if (auto r = log.open(o.candump, iface); !r) throw std::runtime_error(r.error().message());
  std::signal(SIGINT, onTiltSignal);
  std::signal(SIGTERM, onTiltSignal);
  const auto t0 = std::chrono::steady_clock::now();
  long n = 0;
  while (!gInterrupted && (o.count <= 0 || n < o.count)) {
    if (o.duration > 0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() >= o.duration) break;
    auto f = bus.receive(std::chrono::milliseconds(100));
    if (!f) {
      if (f.error().code == std::errc::timed_out) continue;
      throw std::runtime_error(f.error().message());
    }
    ++n;
    log.write(*f);
    if (o.json)
      std::printf("{\"stamp\":%s,\"kernel_stamp\":%s,\"frame\":\"%s\",\"text\":\"%s\"}\n", f->stamp.toString().c_str(),
                  f->kernelStamp ? "true" : "false", f->toString().c_str(), jsonEscape(describeFrame(*f)).c_str());
    else
      std::printf("%s %-22s %s\n", f->stamp.toString().c_str(), f->toString().c_str(), describeFrame(*f).c_str());
    std::fflush(stdout);
  }
  if (auto r = log.close(); !r) throw std::runtime_error(r.error().message());
  std::fprintf(stderr, "tilt monitor: %ld frames, %llu error frames, %llu without a kernel stamp\n", n,
               (unsigned long long)bus.counters().errorFrames, (unsigned long long)bus.counters().userStamps);
  return 0;
}

int runSimulate(const TiltOptions& o) {
  drivers::canopen::sim::NodSimulationOptions s;
  s.drive = driveConfig(o);
  s.sweeps = o.sweeps;
  s.candumpPath = o.candump;
  s.interface = o.interface;
  auto kind = drivers::canopen::sim::parseFaultKind(o.fault);
  if (!kind) throw std::runtime_error(kind.error().message());
  s.fault = *kind;
  s.faultAtSeconds = o.faultAt;
  s.onEvent = printEvent;
  auto r = drivers::canopen::sim::runNodSimulation(s, [&](const drivers::TiltSample& x) {
    if (o.samples || o.json) printSample(x, o.json);
  });
  if (!r) throw std::runtime_error(r.error().message());
  std::fflush(stdout);
  std::fprintf(stderr, "tilt simulate: %d sweeps in %.3f s simulated, %llu frames%s%s\n", o.sweeps, r->seconds,
               (unsigned long long)r->frames, o.candump.empty() ? "" : " written to ", o.candump.c_str());
  printCounters(r->drive);
  return 0;
}

const bool registered = registerCommand(
    "tilt", "Tilt motor (CANopen CiA 402 on SocketCAN): status, nod, home, monitor; simulate with a candump log",
    [](CLI::App& app) {
      auto o = std::make_shared<TiltOptions>();
      app.require_subcommand(1);
      app.add_option("--can", o->can, "SocketCAN interface (default: tilt.interface of --config, else can0)");
      app.add_option("--node", o->node, "CANopen node id 1..127 (default: tilt.node_id, else 5)")->check(CLI::Range(1, 127));
      app.add_option("--config", o->config, "fusedet YAML config whose tilt: section gives the defaults");
      app.add_option("--min-deg", o->minDeg, "lower nodding limit [deg] (default: tilt.min_deg)");
      app.add_option("--max-deg", o->maxDeg, "upper nodding limit [deg] (default: tilt.max_deg)");
      app.add_option("--speed", o->speedDegS, "nodding speed [deg/s] (default: tilt.speed_deg_s)");
      app.add_option("--heartbeat-ms", o->heartbeatMs, "heartbeat period asked of the drive; lost after 3 (default: tilt.heartbeat_ms)")
          ->check(CLI::Range(1, 65535));
      app.add_option("--sdo-timeout-ms", o->sdoTimeoutMs, "SDO response timeout [ms]")->check(CLI::Range(1, 60000))->capture_default_str();
      CLI::App* status = app.add_subcommand("status", "read the drive's identity, state, mode, position and error code over SDO (changes nothing)");
      CLI::App* nod = app.add_subcommand("nod", "bring the drive up and nod until --sweeps/--duration/Ctrl-C; then halt and disable it");
      nod->add_option("--sweeps", o->sweeps, "stop after N sweeps (0 = no limit)")->capture_default_str();
      nod->add_option("--duration", o->duration, "stop after S seconds (0 = no limit)")->capture_default_str();
      nod->add_flag("--samples", o->samples, "print every TiltSample (stamp, angle, velocity)");
      nod->add_flag("--json", o->json, "print every TiltSample as one JSON object");
      nod->add_option("--candump", o->candump, "write every frame sent and received as a candump -l log");
      CLI::App* home = app.add_subcommand("home", "bring the drive up, move to --angle and leave it holding there");
      home->add_option("--angle", o->angleDeg, "angle to hold [deg]")->capture_default_str();
      home->add_option("--duration", o->duration, "give up after S seconds (0 = no limit)")->capture_default_str();
      CLI::App* monitor = app.add_subcommand("monitor", "print every frame on the interface with its CANopen meaning");
      monitor->add_option("--count", o->count, "stop after N frames (0 = no limit)")->capture_default_str();
      monitor->add_option("--duration", o->duration, "stop after S seconds (0 = no limit)")->capture_default_str();
      monitor->add_option("--candump", o->candump, "also write the frames as a candump -l log");
      monitor->add_flag("--json", o->json, "one JSON object per frame: stamp, kernel_stamp (true = the kernel's receive stamp), frame, text");
      CLI::App* simulate = app.add_subcommand(
          "simulate", "drive + simulated motor on an in-process bus in simulated time; all traffic as a candump log");
      simulate->add_option("--sweeps", o->sweeps, "sweeps to nod")->capture_default_str();
      simulate->add_option("--candump", o->candump, "candump -l log to write (every frame on the bus)");
      simulate->add_option("--interface", o->interface, "interface name written in the log")->capture_default_str();
      simulate->add_option("--fault", o->fault, "inject one fault: none emcy silence stall sdo-abort bus-off")->capture_default_str();
      simulate->add_option("--fault-at", o->faultAt, "when to inject it [s after start]")->capture_default_str();
      simulate->add_flag("--samples", o->samples, "print every TiltSample (stamp, angle, velocity)");
      simulate->add_flag("--json", o->json, "print every TiltSample as one JSON object");
      app.footer(
          "The drive is node --node on --can; angles, speed and unit conversion (counts_per_rev, gear_ratio,\n"
          "zero_offset_counts, heartbeat_ms) come from the tilt: section of --config (built-in defaults\n"
          "otherwise). nod/home: NMT reset node, boot-up, SDO configuration (heartbeat, TPDO1 = position +\n"
          "statusword on every SYNC at 100 Hz, profile position mode, speed, acceleration 60 deg/s^2),\n"
          "NMT start, CiA 402 state machine to operation enabled; faults are reported on stderr and\n"
          "recovered. nod/home print one line per event on stdout: 'tilt: operation enabled after N ms',\n"
          "'tilt: sweep I from A to B deg, N samples', 'tilt: fault: CAUSE', 'tilt: recovered in N ms'.\n"
          "Stamps: SocketCAN frames carry the kernel's receive stamp (SO_TIMESTAMPING, else SIOCGSTAMP)\n"
          "moved to CLOCK_MONOTONIC; monitor --json says per frame whether it was the kernel's.\n"
          "Counters go to stderr at the end. simulate runs in simulated time (seconds of nodding\n"
          "take milliseconds); stamps in the log start at 1000 s.\n"
          "Examples:\n"
          "  tilt-sim --can vcan0 --node 5 &  fusedet tilt --can vcan0 --node 5 nod --sweeps 4 --samples\n"
          "  fusedet tilt --can can0 status\n"
          "  fusedet tilt --can vcan0 monitor --duration 5 --candump bus.log\n"
          "  fusedet tilt simulate --sweeps 10 --candump nod.log && log2asc -I nod.log can0\n"
          "Exit status: 0 on success; 1 on errors (printed as 'fusedet tilt: error: ...').");
      return [o, status, nod, home, monitor, simulate]() -> int {
        if (status->parsed()) return runStatus(*o);
        if (nod->parsed()) return runNod(*o);
        if (home->parsed()) return runHome(*o);
        if (monitor->parsed()) return runMonitor(*o);
        if (simulate->parsed()) return runSimulate(*o);
        return 2;
      };
    });

}  // namespace
}  // namespace fusedet::tools
