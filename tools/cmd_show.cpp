// SPDX-License-Identifier: Apache-2.0
// fusedet show: a PNG mosaic of one stack's layers with labels and detections drawn (paper Fig. 8),
// so a person can look at what the detector sees.

#include <cstdio>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "command.h"
#include "data_dir.h"
#include "fusedet/core/dataset.h"
#include "fusedet/fusion/datasets/kitti_import.h"
#include "fusedet/fusion/drawing/detections_file.h"
#include "fusedet/fusion/drawing/mosaic.h"

namespace fusedet::tools {
namespace {

struct ShowOptions {
  std::filesystem::path dataset;
  std::string item;
  std::filesystem::path kitti;
  std::string frame;
  std::filesystem::path detections;
  std::filesystem::path out;
  std::vector<std::string> layers;
  double hueRef = -1;
  int columns = 2;
  double scale = 1.0;
};

int runShow(const ShowOptions& o) {
  if (o.dataset.empty() == o.kitti.empty()) throw std::runtime_error("give either --dataset (with --item) or --kitti");
  DatasetItem item;
  if (!o.dataset.empty()) {
    const std::string id = o.item.empty() ? listDataset(o.dataset).at(0) : o.item;
    item = readDatasetItem(o.dataset, id, o.layers);
  } else {
    const auto ids = fusion::listKittiFrames(o.kitti);
    if (ids.empty()) throw std::runtime_error(o.kitti.string() + ": no frames");
    const std::string id = o.frame.empty() ? ids.front() : o.frame;
    item = fusion::fuseKittiFrame(fusion::readKittiFrame(o.kitti, id), o.kitti.filename().string(), {});
    if (!o.layers.empty()) {
      LayerStack subset(item.stack.width(), item.stack.height());
      for (const std::string& name : o.layers) subset.set(item.stack.at(name));
      item.stack = std::move(subset);
    }
  }
  std::vector<Detection> detections;
  if (!o.detections.empty()) detections = fusion::readDetectionsFile(o.detections);
  fusion::MosaicOptions mo;
  mo.columns = o.columns;
  mo.scale = o.scale;
  if (o.hueRef >= 0) mo.hueReference = o.hueRef;
  const cv::Mat mosaic = fusion::renderMosaic(item.stack, item.labels, detections, mo);
  if (!cv::imwrite(o.out.string(), mosaic)) throw std::runtime_error(o.out.string() + ": cannot write PNG");
  std::printf("%s: %s, %zu layers, %zu labels, %zu detections -> %dx%d mosaic\n", o.out.string().c_str(),
              item.id.c_str(), item.stack.size(), item.labels.size(), detections.size(), mosaic.cols, mosaic.rows);
  return 0;
}

const bool registered = registerCommand(
    "show", "Write a PNG mosaic of a stack's layers with labels and detections drawn (paper Fig. 8)",
    [](CLI::App& app) {
      auto o = std::make_shared<ShowOptions>();
      app.add_option("--dataset", o->dataset, "data set directory (docs/dataset-format.md) to read the stack from");
      app.add_option("--item", o->item, "item id in --dataset, e.g. kitti/000042 (default: the first)");
      app.add_option("--kitti", o->kitti, "instead of --dataset: fuse a frame of this KITTI-layout directory");
      app.add_option("--frame", o->frame, "frame id for --kitti (default: the first)");
      app.add_option("--detections", o->detections,
                     "JSON file {\"detections\":[{\"class\",\"score\",\"x\",\"y\",\"w\",\"h\"}]} (reference "
                     "pixels) to draw in red");
      app.add_option("--out", o->out, "PNG file to write")->required();
      app.add_option("--layers", o->layers, "only these layers, in this order (default: all)");
      app.add_option("--hue-ref", o->hueRef, "add a hue_distance tile for this reference hue in degrees [0, 360)")
          ->check(CLI::Range(0.0, 360.0));
      app.add_option("--columns", o->columns, "tiles per row")->capture_default_str()->check(CLI::Range(1, 16));
      app.add_option("--scale", o->scale, "tile size relative to the camera image")
          ->capture_default_str()
          ->check(CLI::Range(0.05, 4.0));
      app.footer(
          "Tiles: the colour image, then every layer (8-bit as grey, hue as colour, distance colour-\n"
          "mapped near=red far=blue, remission grey; invalid laser cells black). Labels green (van\n"
          "orange), ignore regions grey dashed, labels a teacher drew (fusedet autolabel) cyan, detections red\n"
          "with class and score.\n\n"
          "Examples:\n"
          "  fusedet show --kitti ../shared/data/kitti --frame 000042 --out /tmp/k42.png\n"
          "  fusedet show --dataset /tmp/ds --item kitti/000000 --detections dets.json --out /tmp/d.png\n"
          "  fusedet show --dataset /tmp/ds --layers intensity distance remission --hue-ref 0 --out /tmp/x.png");
      return [o] { return runShow(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
