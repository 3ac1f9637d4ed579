// SPDX-License-Identifier: Apache-2.0
// fusedet import-kitti: KITTI-layout directories -> the project's data set (docs/dataset-format.md),
// through the same fusion code as live data.

#include <cstdio>
#include <filesystem>

#include "command.h"
#include "data_dir.h"
#include "fusedet/fusion/datasets/kitti_import.h"
#include "network_options.h"

namespace fusedet::tools {
namespace {

struct ImportOptions {
  std::vector<std::filesystem::path> roots;
  std::filesystem::path data = defaultDataDir();
  std::filesystem::path out;
  double scale = 0.5;
  int holeFill = 2;
  double minDepth = 0.05;
  std::vector<std::string> classMap;
  bool quiet = false;
  NetworkOptions network;
};

// "SRC=DST": DST "ignore" (or empty) makes SRC an ignore region.
void applyClassMap(fusion::KittiClassMap& map, const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::runtime_error("--class-map '" + spec + "': expected SOURCE=TARGET, e.g. Van=ignore");
  const std::string src = spec.substr(0, eq);
  std::string dst = spec.substr(eq + 1);
  if (dst == "ignore") dst.clear();
  for (auto& [s, d] : map.entries)
    if (s == src) {
      d = dst;
      return;
    }
  map.entries.emplace_back(src, dst);
}

int runImport(const ImportOptions& o) {
  if (o.out.empty()) throw std::runtime_error("--out is required");
  std::vector<std::filesystem::path> roots = o.roots;
  if (roots.empty())
    for (const char* drive : {"kitti", "kitti_0009", "kitti_object_sample"}) roots.push_back(o.data / drive);
  fusion::KittiImportOptions options;
  options.projection.laserLayerScale = o.scale;
  options.projection.holeFillRadius = o.holeFill;
  options.projection.minDepth = o.minDepth;
  for (const std::string& spec : o.classMap) applyClassMap(options.classes, spec);
  options.neural = o.network.load();
  if (options.neural) std::printf("network %s\n", options.neural->identity().text().c_str());

  std::size_t frames = 0, labels = 0;
  for (const auto& root : roots) {
    if (!std::filesystem::is_directory(root)) throw std::runtime_error(root.string() + ": no such directory");
    const std::string group = std::filesystem::absolute(root).lexically_normal().filename().string().empty()
                                  ? std::filesystem::absolute(root).lexically_normal().parent_path().filename().string()
                                  : std::filesystem::absolute(root).lexically_normal().filename().string();
    const auto stats = fusion::importKitti(root, group, o.out, options, [&](const DatasetItem& item) {
      if (!o.quiet) std::printf("  %s: %zu labels\n", item.id.c_str(), item.labels.size());
    });
    const double perFrame = stats.frames ? 1.0 / static_cast<double>(stats.frames) : 0.0;
    std::printf("%s -> group %s: %zu frames, %zu labels (%zu ignore regions), fusion %.1f ms/frame", root.string().c_str(),
                group.c_str(), stats.frames, stats.labels, stats.ignoreRegions, stats.fuseMs * perFrame);
    if (options.neural) std::printf(" (network %.1f ms)", stats.neuralMs * perFrame);
    std::printf("\n");
    frames += stats.frames;
    labels += stats.labels;
  }
  std::printf("data set %s: %zu items written (%zu labels), %zu items in manifest\n", o.out.string().c_str(),
              frames, labels, listDataset(o.out).size());
  return 0;
}

const bool registered = registerCommand(
    "import-kitti",
    "Fuse KITTI frames (image_2, velodyne, calib, label_2) into a fusedet data set",
    [](CLI::App& app) {
      auto o = std::make_shared<ImportOptions>();
      app.add_option("--root", o->roots,
                     "KITTI-layout directory to import; repeat for several. Each becomes one group, named "
                     "after the directory (split train/test by group). Default: kitti, kitti_0009 and "
                     "kitti_object_sample under --data");
      app.add_option("--data", o->data, "root of the shared data, used when no --root is given")
          ->capture_default_str();
      app.add_option("--out", o->out,
                     "data set directory to write (created if missing; items of the same id are replaced, "
                     "others kept)")
          ->required();
      app.add_option("--laser-scale", o->scale, "laser layers' resolution relative to the camera image, (0, 1]")
          ->capture_default_str()
          ->check(CLI::Range(0.01, 1.0));
      app.add_option("--hole-fill", o->holeFill,
                     "fill empty laser cells that have a measured cell within this many cells (0 = off)")
          ->capture_default_str()
          ->check(CLI::Range(0, 50));
      app.add_option("--min-depth", o->minDepth, "[m] drop points closer to the image plane or behind it")
          ->capture_default_str();
      app.add_option("--class-map", o->classMap,
                     "SOURCE=TARGET: map a KITTI class to a project class, or to 'ignore' for an ignore "
                     "region; repeatable. Defaults: Car=car Pedestrian=person Cyclist=bike Van=van (kept "
                     "as a hard negative for car); Truck, Tram, Misc, Person_sitting, DontCare = ignore");
      app.add_flag("-q,--quiet", o->quiet, "print only the per-directory summary");
      addNetworkOptions(app, o->network,
                        "The items record the network (item.json \"network\"); a cascade trained on its layers "
                        "needs the same network at detection time.");
      app.footer(
          "Writes one item per frame: red, green, blue, intensity (8-bit) and hue (degrees) at camera\n"
          "resolution; distance (|p_cam| in metres) and remission ([0,1]) with a validity mask at the\n"
          "laser resolution; with --network also neural_person, neural_bicycle, neural_car ([0,1], the\n"
          "network's best covering anchor score per cell, half the camera resolution). Format:\n"
          "docs/dataset-format.md.\n\n"
          "Examples:\n"
          "  fusedet import-kitti --out /tmp/kitti-ds                  # all three shared drives\n"
          "  fusedet import-kitti --root ../shared/data/kitti --out ds --class-map Van=ignore\n"
          "  fusedet import-kitti --root a --root b --out ds --laser-scale 0.25 --hole-fill 3\n"
          "  fusedet import-kitti --out ds --network darknet --networks-dir ../shared/models");
      return [o] { return runImport(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
