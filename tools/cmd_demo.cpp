// fusedet demo: the main job on its embedded default - the most complete pipeline that exists,
// run on the real KITTI frames in ../shared/data.

#include <Eigen/Core>
#include <cmath>
#include <cstdio>
#include <map>

#include "command.h"
#include "data_dir.h"
#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/kitti.h"

namespace fusedet::tools {
namespace {

struct DemoOptions {
  std::filesystem::path data = defaultDataDir();
  std::string drive = "kitti";
  std::string frame;  // empty = first frame of the drive
};

int runDemo(const DemoOptions& o) {
  const auto root = o.data / o.drive;
  if (!std::filesystem::is_directory(root))
    throw std::runtime_error(root.string() + ": no such data directory (set --data or FUSEDET_DATA)");
  const auto ids = fusion::listKittiFrames(root);
  if (ids.empty()) throw std::runtime_error(root.string() + ": no frames");
  const std::string id = o.frame.empty() ? ids.front() : o.frame;
  const fusion::KittiFrame f = fusion::readKittiFrame(root, id);

  std::printf("fusedet demo: KITTI %s frame %s (%zu frames in drive)\n", o.drive.c_str(), id.c_str(),
              ids.size());
  std::printf("camera    %d x %d BGR\n", f.image.cols, f.image.rows);

  // Points in front of the camera that land inside the image: the part fusion will use.
  const Eigen::Matrix<double, 3, 4> P = f.calib.veloToImage();
  std::size_t inImage = 0;
  double minRange = INFINITY, maxRange = 0, meanRemission = 0;
  for (const auto& p : f.points.points) {
    const Eigen::Vector3d x = P * Eigen::Vector4d(p.x, p.y, p.z, 1);
    if (x.z() <= 0) continue;
    const double u = x.x() / x.z(), v = x.y() / x.z();
    if (u < 0 || v < 0 || u >= f.image.cols || v >= f.image.rows) continue;
    ++inImage;
    const double r = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z);
    minRange = std::min(minRange, r);
    maxRange = std::max(maxRange, r);
    meanRemission += p.remission;
  }
  std::printf("velodyne  %zu points, %zu project into the image (range %.2f..%.2f m, mean remission %.3f)\n",
              f.points.size(), inImage, minRange, maxRange, inImage ? meanRemission / inImage : 0.0);

  std::map<std::string, int> counts;
  for (const Label& l : f.labels) counts[l.ignore ? "ignore(" + l.sourceClass + ")" : l.className]++;
  std::printf("labels    %zu:", f.labels.size());
  for (const auto& [name, n] : counts) std::printf(" %s=%d", name.c_str(), n);
  std::printf("\n");
  for (const Label& l : f.labels)
    if (!l.ignore)
      std::printf("  %-7s box x=%.1f y=%.1f w=%.1f h=%.1f occlusion=%d\n", l.className.c_str(), l.box.x,
                  l.box.y, l.box.w, l.box.h, l.occlusion);
  return 0;
}

const bool registered = registerCommand(
    "demo",
    "Run the most complete pipeline on one real KITTI frame and print what it holds",
    [](CLI::App& app) {
      auto o = std::make_shared<DemoOptions>();
      app.add_option("--data", o->data, "root of the shared data (kitti/, kitti_0009/, ...)")
          ->capture_default_str();
      app.add_option("--drive", o->drive, "drive directory under --data")->capture_default_str();
      app.add_option("--frame", o->frame, "frame id, e.g. 000042 (default: the first)");
      return [o] { return runDemo(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
