// SPDX-License-Identifier: Apache-2.0
// USB: VID:PID[:SERIAL] parsing (with fuzzing), resolution of a device to its /dev nodes on a fake
// sysfs tree laid out as the kernel does for an FTDI adapter, a UVC camera behind a hub and a
// CDC-ACM device, and picking exactly one device. libusb itself needs a USB bus: the real-kernel tier.

#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "fusedet/drivers/usb/sysfs.h"
#include "fusedet/drivers/usb/usb_devices.h"
#include "fusedet/drivers/usb/usb_match.h"

namespace {

using namespace fusedet::drivers::usb;
namespace fs = std::filesystem;

TEST(UsbMatch, ParsesVidPidAndSerial) {
  auto m = parseUsbMatch("0403:6001");
  ASSERT_TRUE(m) << m.error().message();
  EXPECT_EQ(m->vendor, 0x0403);
  EXPECT_EQ(m->product, 0x6001);
  EXPECT_FALSE(m->serial);
  EXPECT_EQ(m->toString(), "0403:6001");
  auto s = parseUsbMatch("046D:0825:A1B2:C3");  // the serial may contain ':'
  ASSERT_TRUE(s);
  EXPECT_EQ(s->vendor, 0x046d);
  EXPECT_EQ(s->product, 0x0825);
  EXPECT_EQ(s->serial, "A1B2:C3");
  EXPECT_EQ(s->toString(), "046d:0825:A1B2:C3");
  EXPECT_EQ(parseUsbMatch("1:2")->vendor, 1);
}

TEST(UsbMatch, RejectsWithAReason) {
  const auto err = [](const char* text) { return parseUsbMatch(text).error().context; };
  EXPECT_EQ(err("04036001"), "USB device '04036001': no ':' between vendor and product id "
                             "(expected VID:PID[:SERIAL][@PORT], VID and PID in hex, e.g. 0403:6001 or 046d:0825@1-2.3)");
  EXPECT_NE(err("0403x:6001").find("vendor id '0403x' is not 1-4 hex digits"), std::string::npos);
  EXPECT_NE(err("04031:6001").find("vendor id '04031'"), std::string::npos);
  EXPECT_NE(err(":6001").find("vendor id ''"), std::string::npos);
  EXPECT_NE(err("0403:").find("product id ''"), std::string::npos);
  EXPECT_NE(err("0403:60g1").find("product id '60g1'"), std::string::npos);
  EXPECT_NE(err("0403:6001:").find("empty serial"), std::string::npos);
  EXPECT_NE(err("0403:6001:A B").find("space or control"), std::string::npos);
  EXPECT_EQ(parseUsbMatch("").error().code, std::errc::invalid_argument);
}

TEST(UsbMatch, FuzzedTextNeverCrashesAndRoundTrips) {
  std::mt19937 rng(3);
  const std::string alphabet = "0123456789abcdefABCDEFxg: \t\n\x01\xff-@.";
  for (int i = 0; i < 20000; ++i) {
    std::string s(rng() % 16, ' ');
    for (char& c : s) c = alphabet[rng() % alphabet.size()];
    auto m = parseUsbMatch(s);
    if (!m) continue;
    auto again = parseUsbMatch(m->toString());
    ASSERT_TRUE(again) << s;
    EXPECT_EQ(again->vendor, m->vendor);
    EXPECT_EQ(again->product, m->product);
    EXPECT_EQ(again->serial, m->serial);
    EXPECT_EQ(again->port, m->port);
  }
}

TEST(UsbMatch, PortNamesThePlaceOnTheBus) {
  auto m = parseUsbMatch("046d:0825@1-2.3");
  ASSERT_TRUE(m) << m.error().message();
  EXPECT_EQ(m->port, "1-2.3");
  EXPECT_FALSE(m->serial);
  EXPECT_EQ(m->toString(), "046d:0825@1-2.3");
  EXPECT_TRUE(m->atPort("1-2.3"));
  EXPECT_FALSE(m->atPort("1-2"));
  auto both = parseUsbMatch("0403:6001:FT1@3-1");
  ASSERT_TRUE(both);
  EXPECT_EQ(both->serial, "FT1");
  EXPECT_EQ(both->port, "3-1");
  auto atInSerial = parseUsbMatch("0403:6001:A@B");  // not a port: part of the serial
  ASSERT_TRUE(atInSerial);
  EXPECT_EQ(atInSerial->serial, "A@B");
  EXPECT_FALSE(atInSerial->port);
  EXPECT_TRUE(parseUsbMatch("0403:6001")->atPort("9-9"));
  for (const char* bad : {"0403:6001@", "0403:6001@1-", "0403:6001@-2", "0403:6001@1-2..3", "0403:6001@1.2-3", "0403:6001@usb1"}) {
    auto e = parseUsbMatch(bad);
    ASSERT_FALSE(e) << bad;
    EXPECT_NE(e.error().context.find("is not BUS-PORT[.PORT...]"), std::string::npos) << e.error().context;
  }
}

TEST(UsbMatch, MatchesOnIdsAndSerial) {
  const UsbMatch any = *parseUsbMatch("0403:6001");
  const UsbMatch one = *parseUsbMatch("0403:6001:FT123");
  EXPECT_TRUE(any.matches(0x0403, 0x6001, std::nullopt));
  EXPECT_TRUE(any.matches(0x0403, 0x6001, "X"));
  EXPECT_FALSE(any.matches(0x0403, 0x6010, std::nullopt));
  EXPECT_TRUE(one.matches(0x0403, 0x6001, "FT123"));
  EXPECT_FALSE(one.matches(0x0403, 0x6001, "FT124"));
  EXPECT_FALSE(one.matches(0x0403, 0x6001, std::nullopt));  // unknown serial never matches a serial
}

// A sysfs tree as the kernel lays it out: /sys/bus/usb/devices/<name> are symlinks into
// /sys/devices/..., interfaces are <name>:<config>.<interface>, and the interface drivers add
// ttyUSB0/tty/ttyUSB0 (usb-serial), tty/ttyACM0 (cdc-acm) or video4linux/videoN (uvcvideo).
class FakeSysfs : public ::testing::Test {
 protected:
  fs::path root = fs::temp_directory_path() / ("fusedet-sysfs-" + std::to_string(::getpid()) + "-" +
                                               ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::path devices = root / "sys/devices/pci0000:00/0000:00:14.0/usb1";

  void SetUp() override {
    fs::remove_all(root);
    fs::create_directories(root / "sys/bus/usb/devices");
    fs::create_directories(root / "sys/class/tty");
    // FTDI adapter on port 1.
    device("1-1", {{"idVendor", "0403"}, {"idProduct", "6001"}, {"serial", "A50285BI"}, {"product", "FT232R USB UART"},
                   {"manufacturer", "FTDI"}});
    dir("1-1/1-1:1.0/ttyUSB0/tty/ttyUSB0");
    // sysfs is full of links pointing back up and across: they must not be followed.
    fs::create_directory_symlink(devices / "1-1", devices / "1-1/1-1:1.0/ttyUSB0/port_back");
    fs::create_directory_symlink(root / "sys/class/tty", devices / "1-1/1-1:1.0/ttyUSB0/tty/ttyUSB0/subsystem");
    fs::create_directory_symlink(devices / "1-1", devices / "1-1/1-1:1.0/driver_like");
    // Hub on port 2 with a UVC camera on its port 3 (video0 capture, video1 metadata).
    device("1-2", {{"idVendor", "05e3"}, {"idProduct", "0610"}});
    dir("1-2/1-2:1.0/1-2-port3");
    device("1-2/1-2.3", {{"idVendor", "046d"}, {"idProduct", "0825"}, {"serial", "  C0FFEE  \n"}});
    dir("1-2/1-2.3/1-2.3:1.0/video4linux/video1");
    dir("1-2/1-2.3/1-2.3:1.0/video4linux/video0");
    dir("1-2/1-2.3/1-2.3:1.0/input/input7/event7");
    dir("1-2/1-2.3/1-2.3:1.1");  // the streaming interface: no node
    // CDC-ACM with two interfaces, the node on the first.
    device("1-4", {{"idVendor", "2341"}, {"idProduct", "0043"}});
    dir("1-4/1-4:1.0/tty/ttyACM0");
    dir("1-4/1-4:1.1");
  }
  void TearDown() override { fs::remove_all(root); }

  void dir(const std::string& rel) { fs::create_directories(devices / rel); }
  void device(const std::string& rel, std::vector<std::pair<std::string, std::string>> attributes) {
    dir(rel);
    for (const auto& [k, v] : attributes) std::ofstream(devices / rel / k) << v << "\n";
    const std::string name = fs::path(rel).filename().string();
    fs::create_directory_symlink(devices / rel, root / "sys/bus/usb/devices" / name);
  }
  UsbSysfs sysfs() const { return UsbSysfs(root / "sys", "/dev"); }
};

TEST_F(FakeSysfs, ResolvesSerialAdapterCameraAndAcm) {
  const UsbSysfs s = sysfs();
  EXPECT_EQ(s.nodes("1-1"), (std::vector<std::string>{"/dev/ttyUSB0"}));
  EXPECT_EQ(s.nodes("1-2.3"), (std::vector<std::string>{"/dev/video0", "/dev/video1"}));
  EXPECT_EQ(s.nodes("1-4"), (std::vector<std::string>{"/dev/ttyACM0"}));
  EXPECT_TRUE(s.nodes("1-2").empty());  // the hub: its child's nodes are not its own
  EXPECT_TRUE(s.nodes("9-9").empty());  // no such device
  EXPECT_EQ(s.attribute("1-1", "serial"), "A50285BI");
  EXPECT_EQ(s.attribute("1-1", "product"), "FT232R USB UART");
  EXPECT_EQ(s.attribute("1-2.3", "serial"), "  C0FFEE");  // trailing whitespace and newline dropped
  EXPECT_FALSE(s.attribute("1-2", "serial"));
  EXPECT_FALSE(s.attribute("9-9", "serial"));
}

TEST_F(FakeSysfs, NodesSortNumericallyAndDevRootIsInjectable) {
  for (int n : {10, 2, 1}) dir("1-2/1-2.3/1-2.3:1.0/video4linux/video" + std::to_string(n));
  const UsbSysfs s(root / "sys", "/tmp/devroot");
  EXPECT_EQ(s.nodes("1-2.3"), (std::vector<std::string>{"/tmp/devroot/video0", "/tmp/devroot/video1",
                                                         "/tmp/devroot/video2", "/tmp/devroot/video10"}));
}

TEST_F(FakeSysfs, DriverNotBoundYetMeansNoNodes) {
  device("1-5", {{"idVendor", "0403"}, {"idProduct", "6001"}});
  dir("1-5/1-5:1.0");
  EXPECT_TRUE(sysfs().nodes("1-5").empty());
}

TEST(UsbSysfs, DeviceNamesAndNodeNames) {
  const std::uint8_t ports[] = {2, 3, 1};
  EXPECT_EQ(UsbSysfs::deviceName(1, ports), "1-2.3.1");
  EXPECT_EQ(UsbSysfs::deviceName(3, std::span<const std::uint8_t>(ports, 1)), "3-2");
  EXPECT_EQ(UsbSysfs::deviceName(2, {}), "usb2");
  EXPECT_TRUE(isDeviceNodeName("ttyUSB0"));
  EXPECT_TRUE(isDeviceNodeName("video12"));
  EXPECT_TRUE(isDeviceNodeName("ttyACM3"));
  EXPECT_FALSE(isDeviceNodeName("video"));
  EXPECT_FALSE(isDeviceNodeName("video4linux"));
  EXPECT_FALSE(isDeviceNodeName("ttyS0"));
  EXPECT_FALSE(isDeviceNodeName("event7"));
}

TEST_F(FakeSysfs, ResolvesANodeFromSysfsAloneAndFollowsARePlug) {
  const UsbSysfs s = sysfs();
  const auto all = listFromSysfs(s);
  ASSERT_EQ(all.size(), 4u);  // adapter, hub, camera, ACM
  EXPECT_EQ(*resolveNodeFromSysfs(s, *parseUsbMatch("046d:0825"), "video"), "/dev/video0");
  EXPECT_EQ(*resolveNodeFromSysfs(s, *parseUsbMatch("0403:6001@1-1"), "ttyUSB"), "/dev/ttyUSB0");
  auto absent = resolveNodeFromSysfs(s, *parseUsbMatch("046d:0990"), "video");
  ASSERT_FALSE(absent);
  EXPECT_EQ(absent.error().code, std::errc::no_such_device);
  EXPECT_EQ(absent.error().context, "usb 046d:0990: no such device connected");
  auto wrongPort = resolveNodeFromSysfs(s, *parseUsbMatch("046d:0825@1-3"), "video");
  ASSERT_FALSE(wrongPort);
  EXPECT_EQ(wrongPort.error().code, std::errc::no_such_device);
  auto hub = resolveNodeFromSysfs(s, *parseUsbMatch("05e3:0610"), "video");
  ASSERT_FALSE(hub);
  EXPECT_EQ(hub.error().code, std::errc::no_such_device_or_address);

  // A second camera of the same kind: ambiguous without a serial or port.
  device("1-6", {{"idVendor", "046d"}, {"idProduct", "0825"}, {"busnum", "1"}, {"devnum", "9"}});
  dir("1-6/1-6:1.0/video4linux/video2");
  auto two = resolveNodeFromSysfs(s, *parseUsbMatch("046d:0825"), "video");
  ASSERT_FALSE(two);
  EXPECT_EQ(two.error().code, std::errc::invalid_argument);
  EXPECT_NE(two.error().context.find("2 devices match (1-2.3 serial   C0FFEE, 1-6 (no serial))"), std::string::npos)
      << two.error().context;
  EXPECT_EQ(*resolveNodeFromSysfs(s, *parseUsbMatch("046d:0825@1-6"), "video"), "/dev/video2");
  EXPECT_EQ(listFromSysfs(s, *parseUsbMatch("046d:0825@1-6")).at(0).address, 9);

  // Unplugged: gone from sysfs. Re-plugged into another socket: a new name and a new node.
  fs::remove(root / "sys/bus/usb/devices/1-2.3");
  fs::remove_all(devices / "1-2/1-2.3");
  fs::remove(root / "sys/bus/usb/devices/1-6");
  fs::remove_all(devices / "1-6");
  EXPECT_EQ(resolveNodeFromSysfs(s, *parseUsbMatch("046d:0825"), "video").error().code, std::errc::no_such_device);
  device("1-7", {{"idVendor", "046d"}, {"idProduct", "0825"}});
  dir("1-7/1-7:1.0");  // uvcvideo not bound yet
  EXPECT_EQ(resolveNodeFromSysfs(s, *parseUsbMatch("046d:0825"), "video").error().code, std::errc::no_such_device_or_address);
  dir("1-7/1-7:1.0/video4linux/video4");
  EXPECT_EQ(*resolveNodeFromSysfs(s, *parseUsbMatch("046d:0825"), "video"), "/dev/video4");
}

TEST(UsbSysfs, MissingOrGarbageTreeListsNothing) {
  EXPECT_TRUE(listFromSysfs(UsbSysfs("/nonexistent-sysfs")).empty());
  const fs::path root = fs::temp_directory_path() / ("fusedet-sysfs-garbage-" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "bus/usb/devices/1-1");
  std::ofstream(root / "bus/usb/devices/1-1/idVendor") << "zz\n";
  std::ofstream(root / "bus/usb/devices/1-1/idProduct") << "0825\n";
  fs::create_directories(root / "bus/usb/devices/1-2");
  std::ofstream(root / "bus/usb/devices/1-2/idVendor") << "123456\n";
  std::ofstream(root / "bus/usb/devices/1-2/idProduct") << "1\n";
  fs::create_directories(root / "bus/usb/devices/1-3");  // no attributes at all
  EXPECT_TRUE(listFromSysfs(UsbSysfs(root)).empty());
  fs::remove_all(root);
}

UsbDeviceInfo dev(std::uint16_t vid, std::uint16_t pid, std::string name, std::optional<std::string> serial,
                  std::vector<std::string> nodes = {}) {
  UsbDeviceInfo d;
  d.vendor = vid;
  d.product = pid;
  d.name = std::move(name);
  d.serial = std::move(serial);
  d.nodes = std::move(nodes);
  return d;
}

TEST(UsbSelect, ExactlyOneMustMatch) {
  const std::vector<UsbDeviceInfo> devices{dev(0x0403, 0x6001, "1-1", "A"), dev(0x0403, 0x6001, "1-3", std::nullopt),
                                           dev(0x046d, 0x0825, "1-2.3", "C", {"/dev/video0", "/dev/video1"})};
  auto cam = selectOne(devices, *parseUsbMatch("046d:0825"));
  ASSERT_TRUE(cam);
  EXPECT_EQ(cam->name, "1-2.3");
  auto two = selectOne(devices, *parseUsbMatch("0403:6001"));
  ASSERT_FALSE(two);
  EXPECT_EQ(two.error().context,
            "usb 0403:6001: 2 devices match (1-1 serial A, 1-3 (no serial)); add the serial (VID:PID:SERIAL) or the port (VID:PID@PORT)");
  auto bySerial = selectOne(devices, *parseUsbMatch("0403:6001:A"));
  ASSERT_TRUE(bySerial);
  EXPECT_EQ(bySerial->name, "1-1");
  auto none = selectOne(devices, *parseUsbMatch("0403:6015"));
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().code, std::errc::no_such_device);
  EXPECT_EQ(none.error().context, "usb 0403:6015: no such device connected");
}

TEST(UsbSelect, NodeOfAKind) {
  const UsbDeviceInfo cam = dev(0x046d, 0x0825, "1-2.3", "C", {"/dev/video0", "/dev/video1"});
  EXPECT_EQ(*nodeOf(cam, "video"), "/dev/video0");
  auto tty = nodeOf(cam, "ttyUSB");
  ASSERT_FALSE(tty);
  EXPECT_EQ(tty.error().context, "usb 046d:0825 at 1-2.3: no /dev/ttyUSB* node (yet)");
}

}  // namespace
