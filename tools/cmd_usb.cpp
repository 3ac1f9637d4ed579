// SPDX-License-Identifier: Apache-2.0
// fusedet usb: USB devices through libusb.
//   list [VID:PID[:SERIAL][@PORT]]   devices with their sysfs position, strings and /dev nodes
//   reset VID:PID[:SERIAL][@PORT]    reset the one matching device (it re-enumerates)
//   watch [VID:PID[:SERIAL][@PORT]]  print hotplug arrivals and departures

#include <atomic>
#include <csignal>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <thread>

#include "command.h"
#include "device_exit.h"
#include "fusedet/drivers/usb/hotplug.h"
#include "fusedet/drivers/usb/usb_devices.h"

namespace fusedet::tools {
namespace {

using namespace drivers::usb;
using nlohmann::json;

std::atomic<bool> gStop{false};
extern "C" void onUsbSignal(int) { gStop = true; }

struct UsbOptions {
  std::string match;
  bool json = false;
  double duration = 0;
  long count = 0;
};

int report(const char* command, const UsbOptions& o, const Error& e, int code) {
  std::fprintf(stderr, "fusedet usb %s: error: %s\n", command, e.message().c_str());
  if (o.json) std::printf("%s\n", json{{"match", o.match}, {"error", e.message()}, {"exit", code}}.dump().c_str());
  return code;
}

json toJson(const UsbDeviceInfo& d) {
  const auto opt = [](const std::optional<std::string>& s) { return s ? json(*s) : json(nullptr); };
  return json{{"id", d.id()},          {"vendor", hex4(d.vendor)}, {"product", hex4(d.product)},
              {"bus", d.bus},          {"address", d.address},     {"port", d.name},
              {"serial", opt(d.serial)}, {"manufacturer", opt(d.manufacturer)}, {"product_name", opt(d.productName)},
              {"nodes", d.nodes}};
}

void printDevice(const UsbDeviceInfo& d, const char* prefix = "") {
  std::string nodes;
  for (const std::string& n : d.nodes) nodes += " " + n;
  std::printf("%s%-10s %s  %s %s%s%s%s\n", prefix, d.name.c_str(), d.id().c_str(), d.manufacturer.value_or("-").c_str(),
              d.productName.value_or("-").c_str(), d.serial ? ("  serial " + *d.serial).c_str() : "",
              nodes.empty() ? "" : " ", nodes.c_str());
}

// Parses the optional match; an error is returned as an exit code via `code`.
std::optional<UsbMatch> matchOf(const char* command, const UsbOptions& o, int& code) {
  code = kExitOk;
  if (o.match.empty()) return std::nullopt;
  auto m = parseUsbMatch(o.match);
  if (!m) {
    code = report(command, o, m.error(), kExitUsage);
    return std::nullopt;
  }
  return *m;
}

int runList(const UsbOptions& o) {
  int code = kExitOk;
  const auto match = matchOf("list", o, code);
  if (code != kExitOk) return code;
  auto bus = UsbBus::open();
  if (!bus) return report("list", o, bus.error(), kExitError);
  auto devices = (*bus)->list(match);
  if (!devices) return report("list", o, devices.error(), kExitError);
  if (o.json) {
    json all = json::array();
    for (const UsbDeviceInfo& d : *devices) all.push_back(toJson(d));
    std::printf("%s\n", all.dump(2).c_str());
  } else {
    for (const UsbDeviceInfo& d : *devices) printDevice(d);
  }
  if (match && devices->empty()) {
    std::fprintf(stderr, "fusedet usb list: no device matches %s\n", match->toString().c_str());
    return kExitNoDevice;
  }
  return kExitOk;
}

int runReset(const UsbOptions& o) {
  int code = kExitOk;
  const auto match = matchOf("reset", o, code);
  if (code != kExitOk) return code;
  auto bus = UsbBus::open();
  if (!bus) return report("reset", o, bus.error(), kExitError);
  auto done = (*bus)->reset(*match);
  if (!done) return report("reset", o, done.error(), exitCodeFor(done.error()));
  if (o.json)
    std::printf("%s\n", json{{"reset", toJson(*done)}}.dump().c_str());
  else
    printDevice(*done, "reset ");
  return kExitOk;
}

int runWatch(const UsbOptions& o) {
  int code = kExitOk;
  const auto match = matchOf("watch", o, code);
  if (code != kExitOk) return code;
  std::signal(SIGINT, onUsbSignal);
  std::signal(SIGTERM, onUsbSignal);
  std::atomic<long> events{0};
  auto watcher = UsbHotplug::start(match, [&](HotplugEvent e, const UsbDeviceInfo& d) {
    const char* what = e == HotplugEvent::kArrived ? "arrived" : "left";
    if (o.json) {
      json j = toJson(d);
      j["event"] = what;
      std::printf("%s\n", j.dump().c_str());
    } else {
      printDevice(d, e == HotplugEvent::kArrived ? "arrived " : "left    ");
    }
    std::fflush(stdout);
    ++events;
  });
  if (!watcher) return report("watch", o, watcher.error(), exitCodeFor(watcher.error()));
  const auto t0 = std::chrono::steady_clock::now();
  while (!gStop && (o.count <= 0 || events < o.count) &&
         (o.duration <= 0 || std::chrono::steady_clock::now() - t0 < std::chrono::duration<double>(o.duration)))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  (*watcher)->stop();
  return kExitOk;
}

const bool registered = registerCommand(
    "usb", "USB devices via libusb: list (with /dev nodes), reset, watch hotplug events",
    [](CLI::App& app) {
      auto o = std::make_shared<UsbOptions>();
      app.require_subcommand(1);
      CLI::App* list = app.add_subcommand("list", "list USB devices (all, or those matching VID:PID[:SERIAL][@PORT]) with their /dev nodes");
      list->add_option("MATCH", o->match, "VID:PID[:SERIAL][@PORT] in hex, e.g. 0403:6001 or 0403:6001@1-2 (PORT as in /sys/bus/usb/devices)");
      list->add_flag("--json", o->json, "a JSON array: id, vendor, product, bus, address, port, serial, manufacturer, product_name, nodes[]");
      CLI::App* reset = app.add_subcommand("reset", "reset the one device matching VID:PID[:SERIAL][@PORT] (USBDEVFS_RESET; it re-enumerates)");
      reset->add_option("MATCH", o->match, "VID:PID[:SERIAL][@PORT] in hex")->required();
      reset->add_flag("--json", o->json, "print {\"reset\": device} (or the error object)");
      CLI::App* watch = app.add_subcommand("watch", "print hotplug arrivals (devices present first) and departures until --duration/--count/Ctrl-C");
      watch->add_option("MATCH", o->match, "VID:PID[:SERIAL][@PORT] in hex (default: every device)");
      watch->add_option("--duration", o->duration, "stop after S seconds (0 = no limit)")->capture_default_str();
      watch->add_option("--count", o->count, "stop after N events (0 = no limit)")->capture_default_str();
      watch->add_flag("--json", o->json, "one JSON object per event: the list fields plus event (arrived|left)");
      const std::string footer = std::string(
                     "Strings (serial, manufacturer, product) and /dev nodes (ttyUSB*, ttyACM*, video*) come from sysfs,\n"
                     "so listing needs no permission on the device; reset needs write access to /dev/bus/usb (root).\n"
                     "A node may be missing for a moment after an arrival, until the interface driver binds.\n"
                     "Examples:\n"
                     "  fusedet usb list\n"
                     "  fusedet usb list 0403:6001 --json | jq -r '.[0].nodes[0]'\n"
                     "  fusedet usb reset 0403:6001:A50285BI\n"
                     "  fusedet usb watch 046d:0825 --json\n") +
                 kDeviceExitHelp;
      for (CLI::App* a : {&app, list, reset, watch}) a->footer(footer);
      return [o, list, reset, watch]() -> int {
        if (list->parsed()) return runList(*o);
        if (reset->parsed()) return runReset(*o);
        if (watch->parsed()) return runWatch(*o);
        return kExitUsage;
      };
    });

}  // namespace
}  // namespace fusedet::tools
