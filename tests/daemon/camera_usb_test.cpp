// SPDX-License-Identifier: Apache-2.0
// camera.usb: CameraSource names its camera by USB id against a fake sysfs tree (the kernel's
// layout: /sys/bus/usb/devices/<port> -> the device, <port>:1.0/video4linux/videoN). The id is
// looked up before every open, an absent camera is reported by its id, and a camera re-plugged
// into another socket is found under its new node. The "nodes" are regular files, so opening one
// fails with "not a character device": that error names the node the source chose.

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <thread>

#include "fusedet/daemon/camera_source.h"

using namespace fusedet::daemon;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

class NullSink : public SensorSink {
 public:
  void onScan(fusedet::drivers::LaserScan) override {}
  void onTilt(fusedet::drivers::TiltSample) override {}
  void onFrame(fusedet::drivers::CameraFrame) override { ++frames; }
  void onScene(PairedScene) override {}
  void onEndOfStream() override {}
  void awaitRoom(const std::atomic<bool>&) override {}
  std::atomic<int> frames{0};
};

class CameraUsb : public ::testing::Test {
 protected:
  fs::path root = fs::temp_directory_path() / ("fusedet-camera-usb-" + std::to_string(::getpid()));
  fs::path devices = root / "sys/devices/pci0000:00/0000:00:14.0/usb1";

  void SetUp() override {
    fs::remove_all(root);
    fs::create_directories(root / "sys/bus/usb/devices");
    fs::create_directories(root / "dev");
  }
  void TearDown() override { fs::remove_all(root); }

  // A UVC camera at `port` whose capture node is /dev/video<n> (a regular file here).
  void plug(const std::string& port, int n, const std::string& serial = "") {
    const fs::path d = devices / port;
    fs::create_directories(d / (port + ":1.0/video4linux/video" + std::to_string(n)));
    std::ofstream(d / "idVendor") << "046d\n";
    std::ofstream(d / "idProduct") << "0825\n";
    if (!serial.empty()) std::ofstream(d / "serial") << serial << "\n";
    fs::create_directory_symlink(d, root / "sys/bus/usb/devices" / port);
    std::ofstream(root / ("dev/video" + std::to_string(n))) << "not a camera";
  }
  void unplug(const std::string& port) {
    fs::remove(root / "sys/bus/usb/devices" / port);
    fs::remove_all(devices / port);
  }
  fusedet::drivers::usb::UsbSysfs sysfs() const { return fusedet::drivers::usb::UsbSysfs(root / "sys", root / "dev"); }

  static Config::Camera config(const std::string& usb) {
    Config::Camera c;
    c.device = "/nonexistent/fusedet-first-guess";
    c.usb = usb;
    c.reconnectMaxS = 0.1;
    return c;
  }
  static bool waitFor(const std::function<bool()>& pred, std::chrono::milliseconds limit = 10s) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
      if (pred()) return true;
      std::this_thread::sleep_for(10ms);
    }
    return pred();
  }
  static std::string lastError(const CameraSource& s) { return s.health().at(0).lastError; }
};

TEST_F(CameraUsb, OpensTheNodeOfTheUsbIdAndFindsItAgainAfterARePlug) {
  plug("1-2", 0);
  CameraSource source(config("046d:0825"), sysfs());
  NullSink sink;
  source.start(sink);
  const std::string video0 = "camera " + (root / "dev/video0").string() + ": not a character device";
  ASSERT_TRUE(waitFor([&] { return lastError(source).find(video0) != std::string::npos; })) << lastError(source);

  unplug("1-2");
  ASSERT_TRUE(waitFor([&] { return lastError(source).find("usb 046d:0825: no such device connected") == 0; })) << lastError(source);
  EXPECT_EQ(source.health().at(0).state, "backing off");

  plug("1-4", 3);  // another socket: another node
  const std::string video3 = "camera " + (root / "dev/video3").string() + ": not a character device";
  ASSERT_TRUE(waitFor([&] { return lastError(source).find(video3) != std::string::npos; })) << lastError(source);
  EXPECT_EQ(sink.frames.load(), 0);
  source.stop();
  EXPECT_EQ(source.health().at(0).state, "stopped");
}

TEST_F(CameraUsb, TwoIdenticalCamerasNeedASerialOrAPort) {
  plug("1-2", 0, "AAA");
  plug("1-3", 2, "BBB");
  {
    CameraSource source(config("046d:0825"), sysfs());
    NullSink sink;
    source.start(sink);
    ASSERT_TRUE(waitFor([&] { return lastError(source).find("2 devices match") != std::string::npos; })) << lastError(source);
    EXPECT_NE(lastError(source).find("1-2 serial AAA, 1-3 serial BBB"), std::string::npos) << lastError(source);
  }
  for (const auto& [usb, node] : {std::pair{"046d:0825:BBB", "video2"}, std::pair{"046d:0825@1-2", "video0"}}) {
    CameraSource source(config(usb), sysfs());
    NullSink sink;
    source.start(sink);
    const std::string want = "camera " + (root / "dev" / node).string() + ": not a character device";
    EXPECT_TRUE(waitFor([&] { return lastError(source).find(want) != std::string::npos; })) << usb << ": " << lastError(source);
  }
}

TEST_F(CameraUsb, ABadIdIsAStartupError) {
  try {
    CameraSource source(config("046d:0825@1-"), sysfs());
    FAIL() << "accepted a malformed camera.usb";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("camera.usb: USB device '046d:0825@1-': port '1-' is not BUS-PORT"), std::string::npos)
        << e.what();
  }
}

}  // namespace
