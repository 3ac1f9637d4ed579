// SPDX-License-Identifier: Apache-2.0
// lms291-sim: a SICK LMS 291 on a pseudo-terminal, for tests, peers and demos without hardware.
// Prints "lms291-sim: device <pty>" once the device is up, runs until SIGINT/SIGTERM or
// --duration, then prints its counters as one JSON line.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <iostream>

#include "simulator.h"

using namespace fusedet::drivers::lms291;

int main(int argc, char** argv) {
  sim::SimOptions o;
  double duration = 0, silenceEvery = 0, silenceFor = 0.5, vanishEvery = 0, vanishFor = 1.0;
  int angle = 180;
  double resolution = 0.5;
  std::vector<double> post;
  std::string status = "0x10";
  std::string logPath;

  CLI::App app{
      "lms291-sim - a SICK LMS 291 laser scanner on a pseudo-terminal.\n"
      "Speaks the LMS 2xx telegram protocol (power-on telegram at 9600 baud, baud switching,\n"
      "variant, configuration, status, type, continuous B0 / interlaced / F5 range+remission\n"
      "output paced at the real rate for the baud) and injects faults on request. Bytes the host\n"
      "sends at a speed other than the device's are ignored; output is not delivered while the\n"
      "host's speed differs (a UART would drop it as framing errors).",
      "lms291-sim"};
  auto* link = app.add_option("--link", o.link, "create a pty and this symlink to its slave side (the host opens it)");
  auto* attach = app.add_option("--attach", o.attach,
                                "use this existing tty instead (a socat/qemu pty end or a real serial port); the host's "
                                "speed is not observable there and is taken to match");
  link->excludes(attach);
  attach->excludes(link);
  app.add_option("--type", o.type, "type string (reply to 0x3A); contains S14 = LMS Fast (no 0x3B)")->capture_default_str();
  app.add_option("--power-on-baud", o.powerOnBaud, "speed after power-on (9600 unless the permanent-baud flag is set)")
      ->check(CLI::IsMember({9600, 19200, 38400, 500000}))->capture_default_str();
  app.add_option("--angle", angle, "power-on scan angle [deg]: 180 | 100")->capture_default_str();
  app.add_option("--resolution", resolution, "power-on resolution [deg]: 1 | 0.5 | 0.25")->capture_default_str();
  app.add_option("--status", status, "status byte of every reply (0x10 = normal; e.g. 0x82 = warning + pollution)")
      ->capture_default_str();
  app.add_option("--room-half-width", o.scene.halfWidth, "side walls at x = +-W [m]")->capture_default_str();
  app.add_option("--room-depth", o.scene.depth, "front wall at y = D [m]")->capture_default_str();
  app.add_option("--post", post, "replace the posts by one at X Y RADIUS [m] (default 0.5 2.0 0.2)")->expected(3);
  app.add_option("--log", logPath,
                 "stream the laser scans of this sensor log (fusedet synth-log / fusedet record) instead of the room, "
                 "in order, one per scan, looping at the end; the device powers on in the log's variant and refuses "
                 "a host that asks for another variant or range unit (no resampling)");
  app.add_flag("--trace", o.trace, "log host reads (with the host's speed) and device speed changes to stderr");
  app.add_flag("--counter-beam", o.counterBeam, "beam 0 carries the sent-scan counter: 1000 + n mod 4000 (code units)");
  app.add_option("--flip-rate", o.faults.bitFlipRate, "probability per output byte of one flipped bit")->capture_default_str();
  app.add_option("--drop-rate", o.faults.dropRate, "probability per output byte of losing it")->capture_default_str();
  app.add_option("--garbage-rate", o.faults.garbageRate, "probability per telegram of 1..16 random bytes before it")
      ->capture_default_str();
  app.add_option("--nak-rate", o.faults.nakRate, "probability per valid request of a NAK instead of an answer")
      ->capture_default_str();
  app.add_option("--silence-every", silenceEvery, "fall silent every S seconds (0 = never)")->capture_default_str();
  app.add_option("--silence-for", silenceFor, "length of each silence [s]")->capture_default_str();
  app.add_option("--vanish-every", vanishEvery, "remove the pty every S seconds (0 = never), like an unplugged adapter")
      ->capture_default_str();
  app.add_option("--vanish-for", vanishFor, "how long the pty stays away [s]; then a new one powers on")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed of the fault injection")->capture_default_str();
  app.add_option("--duration", duration, "exit after S seconds (0 = run until SIGINT/SIGTERM)")->capture_default_str();
  app.footer(
      "Examples:\n"
      "  lms291-sim --link /tmp/lms &                    # then: fusedet lms stream /tmp/lms\n"
      "  lms291-sim --link /tmp/lms --flip-rate 0.01     # 1 % corrupted bytes\n"
      "  fusedet synth-log --out /tmp/s.mcap && lms291-sim --link /tmp/lms --log /tmp/s.mcap   # the log's scans\n"
      "  lms291-sim --link /tmp/lms --vanish-every 5 --vanish-for 1\n"
      "  socat pty,raw,link=/tmp/a pty,raw,link=/tmp/b & lms291-sim --attach /tmp/a   # host opens /tmp/b\n"
      "Exit status: 0 after a clean stop, 1 on bad options, an unreadable --log or when the pty cannot be created.");
  CLI11_PARSE(app, argc, argv);
  if (o.link.empty() && o.attach.empty()) {
    std::cerr << "lms291-sim: error: give --link PATH (new pty) or --attach TTY\n";
    return 1;
  }

  o.variant = Variant{angle, static_cast<int>(std::lround(resolution * 100))};
  if (!o.variant.valid()) {
    std::cerr << "lms291-sim: error: --angle " << angle << " --resolution " << resolution << " is not a valid variant\n";
    return 1;
  }
  try {
    o.status = static_cast<std::uint8_t>(std::stoul(status, nullptr, 0));
  } catch (const std::exception&) {
    std::cerr << "lms291-sim: error: --status " << status << " is not a number\n";
    return 1;
  }
  if (!logPath.empty()) {
    auto scans = sim::loadLoggedScans(logPath);
    if (!scans) {
      std::cerr << "lms291-sim: error: --log: " << scans.error().message() << "\n";
      return 1;
    }
    o.variant = scans->variant;
    o.log = std::make_shared<const sim::LoggedScans>(std::move(*scans));
    std::vector<float> first;
    for (float r : o.log->scans.front().ranges)
      if (r > 0) first.push_back(r);
    std::sort(first.begin(), first.end());
    std::printf("lms291-sim: log %s: %zu scans, %d deg / %.2f deg, %s, %s; first scan median range %.2f m\n", logPath.c_str(),
                o.log->scans.size(), o.variant.angleDeg, o.variant.resolutionCdeg / 100.0,
                o.log->unit == Unit::kMm ? "mm" : "cm", o.log->remission ? "range + remission" : "range only",
                first.empty() ? 0.0 : first[first.size() / 2]);
  }
  if (post.size() == 3) o.scene.posts = {sim::Post{post[0], post[1], post[2]}};

  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);  // before the device thread starts

  sim::Simulator device(o);
  if (auto r = device.start(); !r) {
    std::cerr << "lms291-sim: error: " << r.error().message() << "\n";
    return 1;
  }
  std::printf("lms291-sim: device %s linked at %s\n", device.slavePath().c_str(),
              o.link.empty() ? o.attach.c_str() : o.link.c_str());
  std::fflush(stdout);

  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  auto nextSilence = t0 + std::chrono::duration<double>(silenceEvery);
  auto nextVanish = t0 + std::chrono::duration<double>(vanishEvery);
  for (;;) {
    timespec tick{0, 50'000'000};
    if (sigtimedwait(&signals, nullptr, &tick) > 0) break;
    const auto now = Clock::now();
    if (duration > 0 && now - t0 >= std::chrono::duration<double>(duration)) break;
    if (silenceEvery > 0 && now >= nextSilence) {
      device.silence(std::chrono::milliseconds(static_cast<int>(silenceFor * 1000)));
      nextSilence += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(silenceEvery));
    }
    if (vanishEvery > 0 && now >= nextVanish) {
      device.vanish(std::chrono::milliseconds(static_cast<int>(vanishFor * 1000)));
      nextVanish += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(vanishEvery));
    }
  }
  const sim::SimState s = device.state();
  device.stop();
  const sim::SimCounters c = device.counters();
  std::printf(
      "{\"baud\":%d,\"mode\":%d,\"bytes_out\":%llu,\"telegrams_out\":%llu,\"scans_out\":%llu,\"scans_skipped\":%llu,\"scans_stalled\":%llu,"
      "\"telegrams_damaged\":%llu,\"bit_flips\":%llu,\"dropped_bytes\":%llu,\"garbage_bytes\":%llu,\"requests\":%llu,"
      "\"bad_requests\":%llu,\"naks_injected\":%llu,\"ignored_bytes\":%llu,\"undelivered_bytes\":%llu,\"overrun_bytes\":%llu,\"vanishes\":%llu,\"power_ons\":%llu}\n",
      s.baud, s.mode, (unsigned long long)c.bytesOut, (unsigned long long)c.telegramsOut, (unsigned long long)c.scansOut,
      (unsigned long long)c.scansSkipped, (unsigned long long)c.scansStalled, (unsigned long long)c.telegramsDamaged, (unsigned long long)c.bitFlips,
      (unsigned long long)c.droppedBytes, (unsigned long long)c.garbageBytes, (unsigned long long)c.requests,
      (unsigned long long)c.badRequests, (unsigned long long)c.naksInjected, (unsigned long long)c.ignoredBytes,
      (unsigned long long)c.undeliveredBytes, (unsigned long long)c.overrunBytes, (unsigned long long)c.vanishes, (unsigned long long)c.powerOns);
  return 0;
}
