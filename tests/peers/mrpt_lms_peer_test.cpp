// SPDX-License-Identifier: Apache-2.0
// Peer check: MRPT's LMS 2xx driver (mrpt::hwdrivers::CSickLaserSerial, Debian
// libmrpt-hwdrivers-dev) reads scans from our lms291-sim over a pseudo-terminal at 38400 baud.
// It runs its own set-up (baud probing and switch, installation mode, config read/write,
// variant, streaming) and its own telegram parser and CRC: if our simulator (and with it our
// understanding of the protocol) were off, it would get no scans.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mrpt/hwdrivers/CSickLaserSerial.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <string>

#include "../drivers/default_room.h"

namespace {

using Clock = std::chrono::steady_clock;

double expectedRange(double deg) { return fusedet::testing::expectedRoomRange(deg); }

// lms291-sim as a child process; its stdout (device line, then JSON counters) through a pipe.
struct SimProcess {
  pid_t pid = -1;
  FILE* out = nullptr;
  std::string device;

  bool start(const std::string& link) {
    int fds[2];
    if (pipe(fds) != 0) return false;
    pid = fork();
    if (pid == 0) {
      dup2(fds[1], STDOUT_FILENO);
      close(fds[0]);
      close(fds[1]);
      execl(LMS291_SIM, LMS291_SIM, "--link", link.c_str(), "--duration", "120", static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    out = fdopen(fds[0], "r");
    char line[512];
    if (!out || !fgets(line, sizeof line, out)) return false;
    // "lms291-sim: device /dev/pts/N linked at LINK"
    const std::string s = line;
    const auto at = s.find("device ");
    if (at == std::string::npos) return false;
    device = s.substr(at + 7, s.find(' ', at + 7) - at - 7);
    return true;
  }
  // SIGTERM, then the counters line the simulator prints on its way out.
  std::string stop() {
    std::string counters;
    if (pid > 0) {
      kill(pid, SIGTERM);
      char line[2048];
      while (out && fgets(line, sizeof line, out)) counters += line;
      int status = 0;
      waitpid(pid, &status, 0);
      pid = -1;
    }
    if (out) fclose(out);
    out = nullptr;
    return counters;
  }
  ~SimProcess() { stop(); }
};

TEST(MrptPeer, CSickLaserSerialReadsScansFromLms291SimAt38400) {
  char tmpl[] = "/tmp/lms291-peer-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const std::string dir = tmpl;
  SimProcess sim;
  ASSERT_TRUE(sim.start(dir + "/tty"));
  ASSERT_EQ(sim.device.rfind("/dev/", 0), 0u) << sim.device;

  // MRPT sends a request again when its ACK is later than 65 ms (a 15 ms pause, then 50 ms), and
  // pairs replies with requests by their order: when the simulator process is scheduled late
  // (a loaded machine; a real LMS ACKs within 60 ms), every copy is answered, MRPT takes an answer
  // to a copy for the next reply ("Wrong response to installation mode") and initialize() throws.
  // Its own scheduling is not what is checked here, the protocol is: like a supervisor restarting
  // a sensor, a failed set-up is repeated with a fresh driver (port reopened, full set-up), at most
  // 8 times within 45 s (at load 15 about a third of the set-ups fail). A simulator that got the
  // protocol wrong fails every one of them.
  std::unique_ptr<mrpt::hwdrivers::CSickLaserSerial> laser;
  int setups = 0;
  std::string setupErrors;
  const auto setupStart = Clock::now();
  while (!laser && setups < 8 && Clock::now() - setupStart < std::chrono::seconds(45)) {
    ++setups;
    auto l = std::make_unique<mrpt::hwdrivers::CSickLaserSerial>();
    // The link, not /dev/pts/N: a pty number can be reused by another test once this one ends.
    l->setSerialPort(dir + "/tty");
    l->setBaudRate(38400);
    l->setMillimeterMode(true);
    l->setScanFOV(180);
    l->setScanResolution(50);
    try {
      l->initialize();
      laser = std::move(l);
    } catch (const std::exception& e) {
      setupErrors += std::string(" [") + e.what() + "]";
    }
  }
  ASSERT_TRUE(laser) << setups << " set-ups failed:" << setupErrors;

  int scans = 0;
  const auto t0 = Clock::now();
  double firstScanSeconds = -1;
  while (scans < 10 && Clock::now() - t0 < std::chrono::seconds(30)) {
    bool isObs = false, hwError = false;
    mrpt::obs::CObservation2DRangeScan obs;
    laser->doProcessSimple(isObs, obs, hwError);
    if (!isObs) continue;
    ASSERT_EQ(obs.getScanSize(), 361u);
    if (firstScanSeconds < 0) firstScanSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
    int checked = 0;
    for (std::size_t i = 0; i < obs.getScanSize(); ++i) {
      if (!obs.getScanRangeValidity(i)) continue;
      const double deg = i * 0.5;  // 0 deg = right, counter-clockwise, 0.5 deg steps
      EXPECT_NEAR(obs.getScanRange(i), expectedRange(deg), 0.0011) << "beam " << i;
      ++checked;
    }
    EXPECT_GT(checked, 350);
    ++scans;
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  const std::string counters = sim.stop();
  std::filesystem::remove_all(dir);
  std::printf("MRPT CSickLaserSerial: %d set-up(s), %d scans of 361 beams in %.2f s (first after %.2f s); simulator: %s",
              setups, scans, seconds, firstScanSeconds, counters.c_str());
  EXPECT_EQ(scans, 10);
  // MRPT switched the device to 38400 (and leaves it streaming there).
  EXPECT_NE(counters.find("\"baud\":38400"), std::string::npos) << counters;
}

}  // namespace
