// SPDX-License-Identifier: Apache-2.0
// tilt-sim: the CiA 402 motor simulator on a SocketCAN interface (see --help).

#include <CLI/CLI.hpp>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <thread>

#include "fusedet/drivers/canopen/socketcan_bus.h"
#include "motor_simulator.h"
#include "nod_simulation.h"

using namespace fusedet::drivers::canopen;

namespace {
std::atomic<bool> gStop{false};
std::atomic<int> gInject{0};  // 1 = EMCY (SIGUSR1), 2 = stall -> following error (SIGUSR2)
extern "C" void onSignal(int) { gStop = true; }
extern "C" void onUsr1(int) { gInject = 1; }
extern "C" void onUsr2(int) { gInject = 2; }

// Passes frames and time to the simulator; between polls it applies faults asked for by signal
// or by --fault/--fault-after.
class Injector : public CanNode {
 public:
  Injector(sim::MotorSimulator& m, sim::FaultKind kind, double after, std::uint16_t emcyCode)
      : motor_(m), kind_(kind), after_(after), emcyCode_(emcyCode) {}
  void onFrame(const CanFrame& f) override { motor_.onFrame(f); }
  void poll(fusedet::Stamp now) override {
    if (start_.ns == 0) start_ = now;
    if (kind_ != sim::FaultKind::kNone && now - start_ >= static_cast<std::int64_t>(after_ * 1e9)) {
      inject(kind_);
      kind_ = sim::FaultKind::kNone;
    }
    if (int k = gInject.exchange(0); k != 0) inject(k == 1 ? sim::FaultKind::kEmcy : sim::FaultKind::kStall);
    motor_.poll(now);
  }

 private:
  void inject(sim::FaultKind k) {
    std::printf("tilt-sim: injecting %s\n", std::string(sim::toString(k)).c_str());
    std::fflush(stdout);
    switch (k) {
      case sim::FaultKind::kEmcy: motor_.injectEmcy(emcyCode_); break;
      case sim::FaultKind::kSilence: motor_.silence(std::chrono::milliseconds(3000)); break;
      case sim::FaultKind::kStall: motor_.stall(std::chrono::milliseconds(1500)); break;
      case sim::FaultKind::kSdoAbort: motor_.abortSdo(1, abortcode::kGeneral); break;
      case sim::FaultKind::kBusOff: motor_.busOff(std::chrono::milliseconds(300)); break;
      case sim::FaultKind::kNone: break;
    }
  }
  sim::MotorSimulator& motor_;
  sim::FaultKind kind_;
  double after_;
  std::uint16_t emcyCode_;
  fusedet::Stamp start_{};
};
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "tilt-sim - a simulated CiA 402 servo drive (the fusedet tilt motor) on a SocketCAN interface.\n"
      "Speaks CANopen as node --node: NMT, SDO server (expedited and segmented upload), heartbeat\n"
      "producer (0x1017), TPDO1 on SYNC, EMCY; CiA 402 state machine and profile position mode with\n"
      "velocity and acceleration limits. It answers `fusedet tilt --can IFACE --node N ...` and the\n"
      "fusedetd tilt driver. A virtual bus: ip link add dev vcan0 type vcan && ip link set up vcan0.\n"
      "Faults: one at --fault-after S (--fault emcy|silence|stall|sdo-abort|bus-off), SIGUSR1 = EMCY\n"
      "(--emcy-code), SIGUSR2 = stall (following error), or periodic ones (--*-every); a fault reset\n"
      "by the master clears them. Each injection prints 'tilt-sim: injecting KIND'.\n"
      "Runs until SIGINT/SIGTERM or --duration; prints its counters on exit.",
      "tilt-sim"};
  std::string iface;
  sim::MotorSimOptions o;
  sim::FaultSchedule f;
  double duration = 0;
  int emcyCode = 0x2310;
  int silenceMs = 500, stallMs = 1000, busOffMs = 200;
  app.add_option("--can", iface, "SocketCAN interface (e.g. vcan0, can0)")->required();
  app.add_option("--node", o.node, "CANopen node id")->check(CLI::Range(1, 127))->capture_default_str();
  app.add_option("--name", o.deviceName, "device name (0x1008, read by segmented upload)")->capture_default_str();
  app.add_option("--position", o.initialPosition, "position at power-on [counts]")->capture_default_str();
  app.add_option("--max-velocity", o.maxVelocity, "hard velocity limit 0x607F [counts/s]")->capture_default_str();
  app.add_option("--max-acceleration", o.maxAcceleration, "what the motor can do at most [counts/s^2]")->capture_default_str();
  app.add_option("--duration", duration, "seconds to run (0 = until a signal)")->capture_default_str();
  std::string faultName = "none";
  double faultAfter = 0;
  app.add_option("--fault", faultName, "one fault to inject at --fault-after: none emcy silence stall sdo-abort bus-off")
      ->capture_default_str();
  app.add_option("--fault-after", faultAfter, "seconds after start for --fault")->capture_default_str();
  app.add_option("--emcy-every", f.emcyEvery, "drive fault with an EMCY every S seconds")->capture_default_str();
  app.add_option("--emcy-code", emcyCode, "EMCY error code of --emcy-every")->capture_default_str();
  app.add_option("--silence-every", f.silenceEvery, "fall silent (no frames in or out) every S seconds")->capture_default_str();
  app.add_option("--silence-ms", silenceMs, "length of each silence [ms]")->capture_default_str();
  app.add_option("--stall-every", f.stallEvery, "block the motor (following error) every S seconds")->capture_default_str();
  app.add_option("--stall-ms", stallMs, "length of each stall [ms]")->capture_default_str();
  app.add_option("--abort-every", f.abortEvery, "abort the next SDO request (0x08000000) every S seconds")->capture_default_str();
  app.add_option("--bus-off-every", f.busOffEvery, "go bus-off every S seconds (then EMCY 0x8140 and a boot-up)")->capture_default_str();
  app.add_option("--bus-off-ms", busOffMs, "length of each bus-off [ms]")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  f.emcyCode = static_cast<std::uint16_t>(emcyCode);
  f.silenceFor = std::chrono::milliseconds(silenceMs);
  f.stallFor = std::chrono::milliseconds(stallMs);
  f.busOffFor = std::chrono::milliseconds(busOffMs);

  auto faultKind = sim::parseFaultKind(faultName);
  if (!faultKind) {
    std::fprintf(stderr, "tilt-sim: error: %s\n", faultKind.error().message().c_str());
    return 1;
  }
  SocketCanBus bus;
  if (auto r = bus.open(iface); !r) {
    std::fprintf(stderr, "tilt-sim: error: %s\n", r.error().message().c_str());
    return 1;
  }
  sim::MotorSimulator motor(bus, o);
  motor.setSchedule(f);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGUSR1, onUsr1);
  std::signal(SIGUSR2, onUsr2);
  Injector injector(motor, *faultKind, faultAfter, f.emcyCode);
  std::printf("tilt-sim: node %d on %s (%s stamps)\n", o.node, iface.c_str(),
              bus.kernelTimestamping() ? "SO_TIMESTAMPING" : "SIOCGSTAMP");
  std::fflush(stdout);
  std::thread timer;
  if (duration > 0)
    timer = std::thread([duration] {
      for (int i = 0; i < static_cast<int>(duration * 100) && !gStop; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      gStop = true;
    });
  auto r = runNode(bus, injector, gStop);
  gStop = true;
  if (timer.joinable()) timer.join();
  const auto c = motor.counters();
  std::printf("tilt-sim: frames in %llu out %llu, SDO requests %llu aborts %llu, SYNC %llu, TPDO %llu, "
              "heartbeats %llu, EMCY %llu, boots %llu, faults %llu, set-points %llu\n",
              (unsigned long long)c.framesIn, (unsigned long long)c.framesOut, (unsigned long long)c.sdoRequests,
              (unsigned long long)c.sdoAborts, (unsigned long long)c.syncs, (unsigned long long)c.tpdos,
              (unsigned long long)c.heartbeats, (unsigned long long)c.emcys, (unsigned long long)c.boots,
              (unsigned long long)c.faults, (unsigned long long)c.setPoints);
  if (!r) {
    std::fprintf(stderr, "tilt-sim: error: %s\n", r.error().message().c_str());
    return 1;
  }
  return 0;
}
