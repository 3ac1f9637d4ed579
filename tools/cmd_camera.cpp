// SPDX-License-Identifier: Apache-2.0
// fusedet camera: V4L2 cameras.
//   list          every /dev/videoN: driver, card, capabilities, formats, sizes, frame rates
//   grab          capture N frames from one device and write them as PNG files
//   stream        FrameStream as in the daemon: frames until count/duration, with restarts and reopens

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <thread>

#include "command.h"
#include "device_exit.h"
#include "fusedet/drivers/v4l2/camera.h"
#include "fusedet/drivers/v4l2/device_list.h"
#include "fusedet/drivers/v4l2/frame_stream.h"
#include "fusedet/fusion/frame_decode.h"

namespace fusedet::tools {
namespace {

using namespace drivers::v4l2;
using nlohmann::json;

struct CameraOptions {
  std::string devDir = "/dev";
  std::string device;
  long count = 1;
  std::string out;
  std::string format = "auto";
  std::uint32_t width = 640, height = 480;
  double fps = 15;
  std::uint32_t buffers = kMinBuffers;
  int timeoutMs = 2000;
  long restartEvery = 0;
  std::string exposure = "auto", gain = "auto";
  bool raw = false;
  bool json = false;
  long streamCount = 0;  // stream: 0 = no limit
  double duration = 0;  // stream
  int stallMs = 2000;   // stream
};

int reportError(const char* command, const CameraOptions& o, const Error& e) {
  const int code = exitCodeFor(e);
  std::fprintf(stderr, "fusedet camera %s: error: %s\n", command, e.message().c_str());
  if (o.json) std::printf("%s\n", json{{"device", o.device}, {"error", e.message()}, {"exit", code}}.dump().c_str());
  return code;
}

double fpsOf(Fraction f) { return f.valid() ? 1.0 / f.value() : 0.0; }

json describeJson(const CameraDescription& d) {
  json j{{"device", d.device}, {"usable", d.usable()}};
  if (!d.usable()) j["error"] = d.error;
  if (d.caps) {
    j["driver"] = d.caps->driver;
    j["card"] = d.caps->card;
    j["bus"] = d.caps->busInfo;
    j["capabilities"] = d.caps->describe();
  }
  json formats = json::array();
  for (const FormatOffer& f : d.formats) {
    json sizes = json::array();
    for (const SizeRange& s : f.sizes) {
      if (!s.isDiscrete()) {
        sizes.push_back({{"min_width", s.minWidth}, {"max_width", s.maxWidth}, {"step_width", s.stepWidth},
                         {"min_height", s.minHeight}, {"max_height", s.maxHeight}, {"step_height", s.stepHeight}});
        continue;
      }
      json fps = json::array();
      for (const SizeIntervals& si : d.intervals)
        if (si.fourcc == f.fourcc && si.width == s.minWidth && si.height == s.minHeight)
          for (const IntervalRange& r : si.intervals)
            fps.push_back(r.isDiscrete() ? json(fpsOf(r.min)) : json{{"min", fpsOf(r.max)}, {"max", fpsOf(r.min)}});
      sizes.push_back({{"width", s.minWidth}, {"height", s.minHeight}, {"fps", fps}});
    }
    formats.push_back({{"fourcc", fourccToString(f.fourcc)}, {"description", f.description}, {"sizes", sizes}});
  }
  j["formats"] = formats;
  return j;
}

void printDescription(const CameraDescription& d) {
  if (!d.caps) {
    std::printf("%s  not usable: %s\n", d.device.c_str(), d.error.c_str());
    return;
  }
  std::printf("%s  %s  \"%s\"  %s\n", d.device.c_str(), d.caps->driver.c_str(), d.caps->card.c_str(), d.caps->busInfo.c_str());
  if (!d.usable()) std::printf("  not usable: %s\n", d.error.c_str());
  for (const FormatOffer& f : d.formats) {
    std::printf("  %-4s  %s:", fourccToString(f.fourcc).c_str(), f.description.c_str());
    for (const SizeRange& s : f.sizes) {
      std::printf(" %s", s.toString().c_str());
      std::string rates;
      for (const SizeIntervals& si : d.intervals)
        if (si.fourcc == f.fourcc && si.width == s.minWidth && si.height == s.minHeight && s.isDiscrete())
          for (const IntervalRange& r : si.intervals) {
            char buf[32];
            std::snprintf(buf, sizeof buf, "%s%g", rates.empty() ? "" : " ", fpsOf(r.isDiscrete() ? r.min : r.max));
            rates += buf;
            if (!r.isDiscrete()) rates += "..", std::snprintf(buf, sizeof buf, "%g", fpsOf(r.min)), rates += buf;
          }
      if (!rates.empty()) std::printf(" (%s fps)", rates.c_str());
    }
    std::printf("\n");
  }
}

int runList(const CameraOptions& o) {
  const std::vector<std::string> nodes = listVideoNodes(o.devDir);
  json all = json::array();
  int usable = 0;
  for (const std::string& node : nodes) {
    const CameraDescription d = describeCamera(node);
    usable += d.usable() ? 1 : 0;
    if (o.json)
      all.push_back(describeJson(d));
    else
      printDescription(d);
  }
  if (o.json) std::printf("%s\n", all.dump(2).c_str());
  std::fflush(stdout);  // the list before the verdict on stderr
  if (usable == 0) {
    std::fprintf(stderr, "fusedet camera list: no V4L2 capture device in %s (%zu video node(s))\n", o.devDir.c_str(), nodes.size());
    return kExitNoDevice;
  }
  return kExitOk;
}

std::string extensionOf(drivers::PixelFormat f) { return f == drivers::PixelFormat::kMjpeg ? "mjpg" : "yuyv"; }

// The capture configuration from the options; an exit code instead when they are unusable.
std::optional<CameraConfig> configOf(const char* command, const CameraOptions& o, int& exitCode) {
  CameraConfig c;
  c.device = o.device;
  c.format = *parseFormatChoice(o.format);  // CLI11 checked the choice
  c.width = o.width;
  c.height = o.height;
  c.fps = o.fps;
  c.buffers = o.buffers;
  const auto exposure = parseControlSetting(o.exposure), gain = parseControlSetting(o.gain);
  if (!exposure || !gain) {
    std::fprintf(stderr, "fusedet camera %s: error: --%s '%s': expected 'auto' or a non-negative integer\n", command,
                 exposure ? "gain" : "exposure", (exposure ? o.gain : o.exposure).c_str());
    exitCode = kExitUsage;
    return std::nullopt;
  }
  c.controls.exposure = *exposure;
  c.controls.gain = *gain;
  if (const std::string why = c.validate(); !why.empty()) {
    exitCode = reportError(command, o, makeError(std::errc::invalid_argument, why));
    return std::nullopt;
  }
  return c;
}

json countersJson(const CameraCounters& c) {
  return {{"frames", c.frames},           {"bytes", c.bytes},
          {"lost_frames", c.lostFrames},  {"sequence_gaps", c.sequenceGaps},
          {"sequence_resets", c.sequenceResets}, {"error_frames", c.errorFrames},
          {"short_frames", c.shortFrames}, {"host_stamps", c.hostStamps},
          {"stamps_backwards", c.stampsBackwards}, {"timeouts", c.timeouts},
          {"buffer_errors", c.bufferErrors}, {"stream_starts", c.streamStarts}};
}

int runGrab(const CameraOptions& o) {
  int code = kExitOk;
  const auto config = configOf("grab", o, code);
  if (!config) return code;
  const CameraConfig& c = *config;
  if (!o.out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.out, ec);
    if (ec) return reportError("grab", o, Error{ec, o.out + ": cannot create the output directory"});
  }
  V4l2Camera camera(c);
  // The recording hook keeps the raw buffers; files are written after capturing, so slow disks
  // (or a slow emulated machine) never make the driver drop frames.
  std::vector<std::vector<std::uint8_t>> raws;
  // The hook also sees each buffer's own v4l2_buffer.sequence (the kernel's count); the last
  // buffer it saw before readFrame returns is the returned frame's.
  std::uint32_t kernelSequence = 0;
  camera.setRawHook([&](const RawBuffer& b) {
    kernelSequence = b.sequence;
    if (o.raw) raws.emplace_back(b.bytes.begin(), b.bytes.end());
  });
  auto info = camera.start();
  if (!info) return reportError("grab", o, info.error());
  for (const std::string& note : info->notes) std::fprintf(stderr, "fusedet camera grab: %s: %s\n", o.device.c_str(), note.c_str());
  std::vector<drivers::CameraFrame> frames;
  std::vector<std::uint32_t> kernelSequences;
  const std::chrono::milliseconds timeout(o.timeoutMs);
  long restarts = 0;
  while (static_cast<long>(frames.size()) < o.count) {
    auto f = camera.readFrame(timeout);
    if (!f) {
      camera.stop();
      return reportError("grab", o, f.error());
    }
    frames.push_back(std::move(*f));
    kernelSequences.push_back(kernelSequence);
    if (o.restartEvery > 0 && static_cast<long>(frames.size()) % o.restartEvery == 0 &&
        static_cast<long>(frames.size()) < o.count) {
      if (auto r = camera.restartStream(); !r) {
        camera.stop();
        return reportError("grab", o, r.error());
      }
      ++restarts;
    }
  }
  const CameraCounters counters = camera.counters();
  camera.stop();

  json list = json::array();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const drivers::CameraFrame& f = frames[i];
    json j{{"sequence", f.sequence}, {"kernel_sequence", kernelSequences[i]}, {"stamp", f.stamp.toString()}, {"bytes", f.bytes.size()}};
    if (!o.out.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04zu.png", i);
      const std::string path = (std::filesystem::path(o.out) / name).string();
      auto bgr = fusion::decodeCameraFrame(f);
      if (!bgr) return reportError("grab", o, Error{bgr.error().code, o.device + ": " + bgr.error().message()});
      if (!cv::imwrite(path, *bgr)) return reportError("grab", o, makeError(std::errc::io_error, path + ": cannot write"));
      j["file"] = path;
    }
    list.push_back(j);
  }
  if (o.raw && !o.out.empty())
    for (std::size_t i = 0; i < raws.size(); ++i) {
      char name[40];
      std::snprintf(name, sizeof name, "buffer_%04zu.%s", i, extensionOf(info->format.pixelFormat).c_str());
      std::ofstream(std::filesystem::path(o.out) / name, std::ios::binary)
          .write(reinterpret_cast<const char*>(raws[i].data()), static_cast<std::streamsize>(raws[i].size()));
    }
  const json summary{
      {"device", o.device},
      {"driver", info->caps.driver},
      {"card", info->caps.card},
      {"bus", info->caps.busInfo},
      {"format", fourccToString(info->format.fourcc)},
      {"width", info->format.width},
      {"height", info->format.height},
      {"bytes_per_line", info->bytesPerLine},
      {"interval", info->interval.valid() ? std::to_string(info->interval.numerator) + "/" + std::to_string(info->interval.denominator) : ""},
      {"fps", fpsOf(info->interval)},
      {"buffers", info->buffers},
      {"notes", info->notes},
      {"restarts", restarts},
      {"stamps_increasing", counters.stampsBackwards == 0},
      {"raw_buffers", raws.size()},
      {"counters", countersJson(counters)},
      {"frames", list}};
  if (o.json) {
    std::printf("%s\n", summary.dump().c_str());
  } else {
    std::printf("%s: %s \"%s\" %s %ux%u, %s s/frame, %u buffers\n", o.device.c_str(), info->caps.driver.c_str(),
                info->caps.card.c_str(), fourccToString(info->format.fourcc).c_str(), info->format.width,
                info->format.height, summary["interval"].get<std::string>().c_str(), info->buffers);
    for (const json& f : list)
      std::printf("frame %llu  stamp %s  %zu bytes%s%s\n", f["sequence"].get<unsigned long long>(),
                  f["stamp"].get<std::string>().c_str(), f["bytes"].get<std::size_t>(), f.contains("file") ? "  " : "",
                  f.contains("file") ? f["file"].get<std::string>().c_str() : "");
    std::printf("frames %llu, lost %llu in %llu gaps, error frames %llu, short %llu, host stamps %llu, restarts %ld\n",
                (unsigned long long)counters.frames, (unsigned long long)counters.lostFrames,
                (unsigned long long)counters.sequenceGaps, (unsigned long long)counters.errorFrames,
                (unsigned long long)counters.shortFrames, (unsigned long long)counters.hostStamps, restarts);
  }
  return kExitOk;
}

std::atomic<bool> gStreamStop{false};
extern "C" void onCameraSignal(int) { gStreamStop = true; }

// FrameStream as the daemon runs it: stall restarts, reopen after the device vanished.
int runStream(const CameraOptions& o) {
  int code = kExitOk;
  const auto config = configOf("stream", o, code);
  if (!config) return code;
  std::signal(SIGINT, onCameraSignal);
  std::signal(SIGTERM, onCameraSignal);
  FrameStreamTiming timing;
  timing.stallLimit = std::chrono::milliseconds(o.stallMs);
  std::atomic<long> received{0};
  FrameStream stream(*config, [&](const drivers::CameraFrame& f) {
    if (o.streamCount > 0 && received >= o.streamCount) return;
    ++received;
    if (o.json)
      std::printf("%s\n", json{{"sequence", f.sequence}, {"stamp", f.stamp.toString()}, {"bytes", f.bytes.size()}}.dump().c_str());
    else
      std::printf("frame %llu  stamp %s  %zu bytes\n", static_cast<unsigned long long>(f.sequence), f.stamp.toString().c_str(),
                  f.bytes.size());
    std::fflush(stdout);
  }, timing);
  stream.start();
  const auto t0 = std::chrono::steady_clock::now();
  while (!gStreamStop && (o.streamCount <= 0 || received < o.streamCount) &&
         (o.duration <= 0 || std::chrono::steady_clock::now() - t0 < std::chrono::duration<double>(o.duration)))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  stream.stop();
  const FrameStreamCounters c = stream.counters();
  const json summary{{"device", o.device},           {"received", received.load()},     {"counters", countersJson(c.camera)},
                     {"stalls", c.stalls},           {"stream_restarts", c.streamRestarts}, {"reopens", c.reopens},
                     {"failed_opens", c.failedOpens}, {"last_error", c.lastError}};
  if (o.json)
    std::printf("%s\n", json{{"summary", summary}}.dump().c_str());
  else
    std::fprintf(stderr, "camera: %ld frames, %llu lost, %llu stalls, %llu stream restarts, %llu reopens, %llu failed opens%s%s\n",
                 received.load(), (unsigned long long)c.camera.lostFrames, (unsigned long long)c.stalls,
                 (unsigned long long)c.streamRestarts, (unsigned long long)c.reopens, (unsigned long long)c.failedOpens,
                 c.lastError.empty() ? "" : "; last error: ", c.lastError.c_str());
  if (received == 0) {
    std::fprintf(stderr, "fusedet camera stream: error: no frame from %s%s%s\n", o.device.c_str(),
                 c.lastError.empty() ? "" : ": ", c.lastError.c_str());
    return kExitTimeout;
  }
  return kExitOk;
}

const bool registered = registerCommand(
    "camera", "V4L2 cameras: list devices and their formats; grab frames to PNG files",
    [](CLI::App& app) {
      auto o = std::make_shared<CameraOptions>();
      app.require_subcommand(1);
      CLI::App* list = app.add_subcommand(
          "list", "list every /dev/videoN: driver, card, bus, and for capture devices every format, size and frame rate");
      list->add_flag("--json", o->json, "a JSON array: device, usable, error, driver, card, bus, capabilities, formats[fourcc, description, sizes[width, height, fps[]]]");
      list->add_option("--dev-dir", o->devDir, "where to look for videoN nodes")->capture_default_str();
      CLI::App* grab = app.add_subcommand(
          "grab", "capture --count frames (mmap streaming, negotiated format) and write them as PNG files to --out");
      grab->add_option("--device", o->device, "V4L2 capture node, e.g. /dev/video0")->required();
      grab->add_option("--count", o->count, "frames to capture")->capture_default_str()->check(CLI::Range(1L, 100000L));
      grab->add_option("--out", o->out, "directory for frame_NNNN.png (created); without it nothing is written");
      grab->add_option("--format", o->format, "yuyv | mjpeg (exactly that, else an error listing what the device offers) | auto (YUYV, else MJPEG)")
          ->capture_default_str()
          ->check(CLI::IsMember({"auto", "yuyv", "mjpeg"}));
      grab->add_option("--width", o->width, "requested width (the nearest offered size is used)")->capture_default_str();
      grab->add_option("--height", o->height, "requested height")->capture_default_str();
      grab->add_option("--fps", o->fps, "requested frame rate (the nearest offered interval is used)")->capture_default_str();
      grab->add_option("--buffers", o->buffers, "mmap buffers to request (4..32)")->capture_default_str();
      grab->add_option("--timeout-ms", o->timeoutMs, "longest wait for one frame")->capture_default_str()->check(CLI::Range(1, 600000));
      grab->add_option("--restart-every", o->restartEvery, "restart the stream (STREAMOFF/STREAMON) after every N frames (0 = never)")
          ->capture_default_str();
      grab->add_option("--exposure", o->exposure, "auto, or a fixed exposure in microseconds")->capture_default_str();
      grab->add_option("--gain", o->gain, "auto, or a fixed gain in device units")->capture_default_str();
      grab->add_flag("--raw", o->raw, "also write each raw buffer as seen by the recording hook (buffer_NNNN.yuyv|.mjpg)");
      grab->add_flag("--json", o->json, "print one JSON summary (format, interval, counters, frames[sequence, kernel_sequence, stamp, bytes, file]); sequence = fusedet's count (continues across restarts), kernel_sequence = the driver's v4l2_buffer.sequence");
      CLI::App* stream = app.add_subcommand(
          "stream", "run the camera as the daemon does (restart a stalled stream, reopen a vanished device) and print frames until --count/--duration/Ctrl-C");
      stream->add_option("--device", o->device, "V4L2 capture node, e.g. /dev/video0")->required();
      stream->add_option("--count", o->streamCount, "stop after N frames (0 = no limit)")->capture_default_str();
      stream->add_option("--duration", o->duration, "stop after S seconds (0 = no limit)")->capture_default_str();
      stream->add_option("--stall-ms", o->stallMs, "no frame this long: restart the stream (twice), then reopen")
          ->capture_default_str()->check(CLI::Range(100, 600000));
      stream->add_flag("--json", o->json, "one JSON object per frame (sequence, stamp, bytes), then {\"summary\": {counters, stalls, stream_restarts, reopens, failed_opens, last_error}}");
      stream->add_option("--format", o->format, "yuyv | mjpeg | auto (as for grab)")
          ->capture_default_str()
          ->check(CLI::IsMember({"auto", "yuyv", "mjpeg"}));
      stream->add_option("--width", o->width, "requested width")->capture_default_str();
      stream->add_option("--height", o->height, "requested height")->capture_default_str();
      stream->add_option("--fps", o->fps, "requested frame rate")->capture_default_str();
      stream->add_option("--buffers", o->buffers, "mmap buffers to request (4..32)")->capture_default_str();
      stream->add_option("--exposure", o->exposure, "auto, or a fixed exposure in microseconds")->capture_default_str();
      stream->add_option("--gain", o->gain, "auto, or a fixed gain in device units")->capture_default_str();
      const std::string footer =
          std::string("Frames are captured first and written afterwards, so writing never makes the driver drop frames.\n"
                      "grab reports lost frames (gaps in the driver's sequence numbers), error and short buffers, frames\n"
                      "stamped on the host because the driver's stamps are not CLOCK_MONOTONIC, and whether the stamps\n"
                      "increase. list exits 3 when no node is a usable capture device.\n"
                      "Examples:\n"
                      "  fusedet camera list\n"
                      "  fusedet camera grab --device /dev/video0 --count 5 --out /tmp/frames\n"
                      "  fusedet camera grab --device /dev/video0 --count 100 --restart-every 50 --json | jq .counters\n"
                      "  fusedet camera grab --device /dev/video0 --format mjpeg --exposure 10000 --gain 0 --out /tmp/f\n") +
          kDeviceExitHelp;
      for (CLI::App* a : {&app, list, grab, stream}) a->footer(footer);
      return [o, list, grab, stream]() -> int {
        if (list->parsed()) return runList(*o);
        if (grab->parsed()) return runGrab(*o);
        if (stream->parsed()) return runStream(*o);
        return kExitUsage;
      };
    });

}  // namespace
}  // namespace fusedet::tools
