// SPDX-License-Identifier: Apache-2.0
// fusedet autolabel: a pretrained COCO detector labels a data set as a teacher (rules:
// fusedet/fusion/datasets/teacher_labels.h); people then correct the labels in CVAT
// (fusedet dataset export/import) before training.

#include <cstdio>
#include <filesystem>
#include <memory>

#include "command.h"
#include "fusedet/core/dataset.h"
#include "fusedet/fusion/datasets/teacher_labels.h"

namespace fusedet::tools {
namespace {
namespace fs = std::filesystem;

struct AutolabelOptions {
  fs::path dataset;
  std::string kind;
  std::vector<fs::path> files;
  std::string input;
  int threads = 1;
  fusion::TeacherRule rule;
  bool noVeto = false;
  bool dryRun = false;
  bool quiet = false;
};

int runAutolabel(AutolabelOptions o) {
  if (!(o.rule.uncertainScore > 0 && o.rule.uncertainScore <= o.rule.minScore && o.rule.minScore <= 1))
    throw std::runtime_error("need 0 < --uncertain-score <= --min-score <= 1");
  for (const std::string& c : o.rule.classes)
    if (c != "person" && c != "car" && c != "bike")
      throw std::runtime_error("--classes: '" + c + "' is no class the COCO teacher knows (person, car, bike)");
  o.rule.laserVeto = !o.noVeto;
  fusion::Network network(
      fusion::NetworkSpec{fusion::parseNetworkKind(o.kind), o.files, fusion::parseInputSize(o.input), o.threads});
  std::printf("teacher   %s\n", network.identity().text().c_str());
  const std::vector<DatasetEntry> entries = readDatasetManifest(o.dataset);
  fusion::TeacherCounts total;
  std::size_t items = 0;
  for (const DatasetEntry& e : entries) {
    const DatasetItem item = readDatasetItem(o.dataset, e.id);
    fusion::TeacherCounts counts;
    const Labels taught = fusion::teachStack(network, item.stack, o.rule, counts);
    const Labels merged = fusion::mergeTeacherLabels(item.labels, taught, o.rule, counts);
    if (!o.dryRun) writeDatasetItemLabels(o.dataset, e.id, merged);
    if (!o.quiet)
      std::printf("  %s: %zu labels, %zu ignore regions, %zu vetoed by the laser, %zu under human labels\n", e.id.c_str(),
                  counts.labels, counts.ignoreRegions, counts.vetoed, counts.underHuman);
    total += counts;
    ++items;
  }
  std::printf("autolabel %zu items: %zu teacher labels, %zu ignore regions, %zu vetoed, %zu under human labels%s\n",
              items, total.labels, total.ignoreRegions, total.vetoed, total.underHuman,
              o.dryRun ? " (dry run: nothing written)" : "");
  return 0;
}

const bool registered = registerCommand(
    "autolabel", "Label a data set with a pretrained COCO detector as teacher (labels marked origin teacher)",
    [](CLI::App& app) {
      auto o = std::make_shared<AutolabelOptions>();
      app.add_option("DATASET", o->dataset, "a data set folder (docs/dataset-format.md) with red, green, blue layers")
          ->required()
          ->check(CLI::ExistingDirectory);
      app.add_option("--kind", o->kind, "network kind: darknet (cfg + weights) or yolov5-onnx (one .onnx)")->required();
      app.add_option("--model", o->files, "the network's file(s): darknet: the .cfg then the .weights; yolov5-onnx: the .onnx")
          ->required();
      app.add_option("--input", o->input, "input size WxH the network runs at, e.g. 832x256")->required();
      app.add_option("--classes", o->rule.classes, "classes to label (person, car, bike)")->capture_default_str();
      app.add_option("--min-score", o->rule.minScore, "a box this sure becomes a label")->capture_default_str();
      app.add_option("--uncertain-score", o->rule.uncertainScore,
                     "a box at least this sure but below --min-score becomes an ignore region")
          ->capture_default_str();
      app.add_flag("--no-laser-veto", o->noVeto, "keep boxes where depth is expected but none is measured");
      app.add_flag("--replace-human", o->rule.replaceHuman,
                   "drop human labels too (a teacher-only data set); default: keep them, and leave out teacher boxes "
                   "over them");
      app.add_flag("--dry-run", o->dryRun, "count, write nothing");
      app.add_option("--threads", o->threads, "OpenCV threads while the network runs (1: the same labels every run)")
          ->capture_default_str();
      app.add_flag("-q,--quiet", o->quiet, "only the summary line");
      app.footer(
          "Per item: the network runs once on the camera image (red, green, blue layers); its COCO person, bicycle\n"
          "and car boxes become project classes (a person riding a bicycle = bike; fusedet/fusion/neural/\n"
          "coco_detections.h). A box scoring >= --min-score becomes a label, one between --uncertain-score and\n"
          "--min-score an ignore region; every one is marked origin \"teacher\" (fusedet show draws them dashed, CVAT\n"
          "shows them as source auto). Laser veto: a box is dropped when at least half of the distance layer's cells\n"
          "around it are measured but fewer than 2 % inside it are - depth was expected and none came back.\n"
          "Earlier teacher labels are replaced on every run; human labels are kept, and a teacher box overlapping one\n"
          "(IoU >= 0.5) is left out.\n"
          "Teachers (../shared/models, SOURCE.md): Yolo-Fastest-XL (darknet, public domain) or YOLOv5n (yolov5-onnx,\n"
          "AGPL-3.0: yours to use, not shipped with fusedet).\n"
          "Examples:\n"
          "  fusedet autolabel data/robot --kind darknet --model yolo-fastest-1.1-xl.cfg \\\n"
          "      --model yolo-fastest-1.1-xl.weights --input 832x256\n"
          "  fusedet autolabel data/robot --kind yolov5-onnx --model yolov5n_256x832.onnx --input 832x256 --replace-human\n"
          "Exit status: 0 done; 1 on errors (a network that does not load, a data set without camera layers).");
      return [o] { return runAutolabel(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
