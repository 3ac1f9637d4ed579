// SPDX-License-Identifier: Apache-2.0
#pragma once
// Config: the daemon's one YAML file (config/fusedet.yaml documents every key and default).
// Loading is strict: unknown keys, wrong types and out-of-range values are errors that name the
// file, the key path and the line.

#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusedet/tracking/tracker.h"

namespace fusedet::daemon {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Config {
  int version = 1;
  std::string logLevel = "info";

  struct Socket {
    std::string path = "/run/fusedet/fusedet.sock";
    int maxClients = 16;
    int maxRequestBytes = 4096;
    int clientQueue = 256;
    int clientSendBuffer = 0;  // bytes (SO_SNDBUF) per client connection; 0 = the system default
    std::string mode = "0660";  // octal: the socket file's mode
    std::string group;          // the socket file's group; "" = the daemon's own
    std::vector<std::string> allowGroups;  // groups whose members may talk; empty = anyone who can open it
  } socket;

  struct Laser {
    std::string device = "/dev/ttyUSB0";
    int baud = 38400;
    int angleDeg = 180;
    double resolutionDeg = 0.5;
    bool remission = false;
    std::string rangeUnit = "mm";  // mm | cm
    double remissionFullScale = 1000.0;  // raw remission value that maps to 1 in the remission layer
    double reconnectMaxS = 5.0;
  } laser;

  struct Tilt {
    std::string interface = "can0";
    int nodeId = 5;
    double minDeg = -30, maxDeg = 30, speedDegS = 15;
    int countsPerRev = 4096;
    double gearRatio = 50;
    long zeroOffsetCounts = 0;
    int heartbeatMs = 100;
  } tilt;

  struct Camera {
    std::string device = "/dev/video0";
    std::string usb;                 // VID:PID[:SERIAL]; non-empty: the video node of that USB camera
    std::string format = "yuyv";     // yuyv | mjpeg | auto
    int width = 640, height = 480, fps = 15;
    int buffers = 4;                 // mmap capture buffers
    std::string exposure = "auto";   // auto | microseconds
    std::string gain = "auto";       // auto | device units
    int stallMs = 2000;              // no frame this long: restart the stream, then reopen
    double reconnectMaxS = 5.0;
    std::string calibration = "/etc/fusedet/camera.yaml";
  } camera;

  struct Fusion {
    std::array<double, 3> rotationRpyDeg{-90, 0, -90};
    std::array<double, 3> translation{0, -0.10, 0};
    std::array<double, 3> tiltAxisOffset{0, 0, 0.05};
    double laserLayerScale = 0.5;
    int holeFillRadius = 2;
    int maxPairSkewMs = 150;
    int tiltWindowMs = 50;
    bool closeOnTilt = true;  // a tilt sample that proves the turn closes a sweep (false: the next scan)
  } fusion;

  // A pretrained network as one more layer source (issue 30; fusion/neural/neural_layers.h): off by
  // default. On, every stack also gets neural_person, neural_bicycle, neural_car from the camera
  // image, and models trained on them must record the same network.
  struct Neural {
    bool enabled = false;
    std::string kind = "darknet";              // darknet | yolov5-onnx
    std::vector<std::string> files;            // empty = the kind's default files in `directory`
    std::string directory = "/usr/share/fusedet/networks";  // relative: to the config's folder
    std::string input = "832x256";             // W x H (darknet: multiples of 32)
    double scale = 0.5;                        // score layers' grid relative to the camera image
    int threads = 1;                           // OpenCV threads of one network run
  } neural;

  struct Detection {
    // Defaults equal boosting::ScanParams{} and GroupParams{} (one meaning for every key).
    std::vector<std::string> models{"/usr/share/fusedet/models/car.json", "/usr/share/fusedet/models/bike.json",
                                    "/usr/share/fusedet/models/person.json"};
    double scaleFactor = 1.1;
    std::array<int, 2> minSize{0, 0};
    std::array<int, 2> maxSize{0, 0};
    double step = 2;  // base-window pixels, scaled with the window (ScanParams::step)
    int minNeighbors = 3;
    bool laserExtent = false;  // boosting::LaserExtentParams::enabled
    int threads = 0;
    // Per class, its own min_neighbors and laser_extent over the two above (same scan); the
    // default is builtInClasses(). A config's `classes:` replaces it.
    struct ClassSettings {
      std::string name;
      int minNeighbors = 3;
      bool laserExtent = false;
    };
    // The library's rule: boosting::classGroupings() of every class with settings of its own
    // (boosting::classesWithOwnDetection(): car), whatever models are loaded.
    static std::vector<ClassSettings> builtInClasses();
    std::vector<ClassSettings> classes = builtInClasses();
  } detection;

  // The tracker after detection (section `tracking`); its defaults are the library's.
  tracking::TrackerParams tracking;

  // The live view (daemon/live/, docs/live-view.md): Foxglove WebSocket protocol and a page.
  struct Live {
    std::string listen;  // "" = off; "PORT" (loopback), "HOST:PORT", "unix:/PATH" (live/listen_address.h)
    std::vector<std::string> layers{"distance", "remission"};  // fused layers sent as images
    int maxViewers = 8;                 // further connections are refused (HTTP 503)
    int viewerQueueBytes = 16 << 20;    // bytes queued for one viewer; a viewer further behind is dropped
  } live;

  struct Replay {
    std::string file;         // MCAP sensor log; non-empty = replay mode (relative: to the config's folder)
    bool realtime = true;     // paced like the recording; false = as fast as possible, nothing dropped
    double speed = 1.0;       // with realtime: 2 = twice the recorded speed
    bool restamp = true;      // stamps shifted so the log starts "now"; false = recorded stamps
    std::string atEnd = "idle";  // exit | idle | loop
  } replay;
};

// Throws ConfigError ("FILE:LINE: key.path: reason").
Config loadConfig(const std::filesystem::path& file);
Config parseConfig(const std::string& yamlText, const std::string& sourceName);
// The effective configuration as YAML, every key present (for --check-config and status).
std::string dumpConfig(const Config& config);
// socket.mode ("0660") as a number; nothing unless 1-4 octal digits.
std::optional<unsigned> parseSocketMode(const std::string& text);

// The config file of the installation `executable` belongs to (the default of fusedetd --config):
// <prefix>/etc/fusedet/fusedet.yaml, where <prefix> is the folder above the executable's bin/, and
// /etc/fusedet/fusedet.yaml for the prefix /usr (the FHS rule GNUInstallDirs applies, taken at run
// time so that one build serves `cmake --install --prefix P` and the /usr Debian package alike).
std::filesystem::path installedConfigFile(const std::filesystem::path& executable);

}  // namespace fusedet::daemon
