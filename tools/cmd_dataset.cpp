// SPDX-License-Identifier: Apache-2.0
// fusedet dataset: look at data sets, combine and cut them, and bring labels in and out through the
// files labelling tools read and write (CVAT for images 1.1, COCO, KITTI label_2).

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "command.h"
#include "data_dir.h"
#include "fusedet/fusion/datasets/kitti_drives.h"
#include "fusedet/core/dataset.h"
#include "fusedet/fusion/datasets/coco_labels.h"
#include "fusedet/fusion/datasets/cvat_labels.h"
#include "fusedet/fusion/datasets/kitti_label_files.h"
#include "fusedet/fusion/datasets/label_exchange.h"
#include "fusedet/sensor_logs/dataset_from_log.h"

namespace fusedet::tools {
namespace {
namespace fs = std::filesystem;

struct DatasetOptions {
  fs::path dataset;
  std::vector<fs::path> inputs;  // merge
  fs::path out;
  fs::path file;  // import
  std::string format;
  std::vector<std::string> maps;
  bool allowUnmatched = false;
  bool json = false;
  std::string by = "log";
  fs::path log;
  sensor_logs::FromLogOptions fromLog;
  fs::path kittiRoot = defaultDataDir();
};

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void writeText(const fs::path& file, const std::string& text) {
  if (file.has_parent_path()) fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  if (!out || !(out << text) || !out.flush()) throw std::runtime_error(file.string() + ": cannot write");
}

int runInfo(const DatasetOptions& o) {
  const std::vector<DatasetEntry> entries = readDatasetManifest(o.dataset);
  std::map<std::string, std::size_t> groups, classes, ignored;
  std::set<std::pair<int, int>> sizes;
  for (const DatasetEntry& e : entries) {
    const DatasetItem item = readDatasetItemLabels(o.dataset, e.id);
    ++groups[e.group];
    sizes.emplace(item.stack.width(), item.stack.height());
    for (const Label& l : item.labels) ++(l.ignore ? ignored : classes)[l.className];
  }
  // The layers of the first item (data sets made by one importer share them).
  std::vector<std::string> layers;
  const DatasetItem first = entries.empty() ? DatasetItem{} : readDatasetItem(o.dataset, entries.front().id);
  for (const Layer& l : first.stack.layers()) {
    const char* type = l.data.depth() == CV_8U ? "u8" : l.data.depth() == CV_16U ? "u16" : "f32";
    layers.push_back(l.name + " " + type + " " + std::to_string(l.width()) + "x" +
                     std::to_string(l.height()) + (l.hasMask() ? " masked" : ""));
  }
  if (o.json) {
    nlohmann::json j{{"items", entries.size()},
                     {"groups", groups},
                     {"labels", classes},
                     {"ignore_regions", ignored},
                     {"layers_of_first_item", layers}};
    j["reference_sizes"] = nlohmann::json::array();
    for (const auto& [w, h] : sizes) j["reference_sizes"].push_back({w, h});
    std::printf("%s\n", j.dump().c_str());
    return 0;
  }
  std::printf("dataset  %s: %zu items in %zu groups\n", o.dataset.c_str(), entries.size(), groups.size());
  for (const auto& [group, n] : groups) std::printf("group    %s %zu\n", group.c_str(), n);
  for (const auto& [w, h] : sizes) std::printf("size     %dx%d\n", w, h);
  for (const auto& [name, n] : classes) std::printf("label    %s %zu\n", name.c_str(), n);
  for (const auto& [name, n] : ignored) std::printf("ignore   %s %zu\n", name.c_str(), n);
  for (const std::string& layer : layers) std::printf("layer    %s\n", layer.c_str());
  return 0;
}

void checkFormat(const std::string& format) {
  if (format != "cvat" && format != "coco" && format != "kitti")
    throw std::runtime_error("--format '" + format + "': use cvat, coco or kitti");
}

int runExport(const DatasetOptions& o) {
  checkFormat(o.format);
  const std::vector<fusion::ExchangeImage> images = fusion::exchangeImages(o.dataset);
  std::size_t labels = 0;
  for (const auto& image : images) labels += image.labels.size();
  if (o.format == "coco") writeText(o.out, fusion::cocoFromImages(images).dump(1) + "\n");
  if (o.format == "cvat") writeText(o.out, fusion::cvatFromImages(images, o.dataset.filename().string()));
  if (o.format == "kitti") fusion::writeKittiLabelFiles(o.out, images);
  std::printf("export   %zu images, %zu labels -> %s (%s)\n", images.size(), labels, o.out.c_str(),
              o.format.c_str());
  return 0;
}

int runImport(const DatasetOptions& o) {
  checkFormat(o.format);
  fusion::LabelClassTable table;
  const std::vector<fusion::ExchangeImage> current = fusion::exchangeImages(o.dataset);
  // A class the data set already has maps to itself, so its own exports read back.
  for (const auto& image : current)
    for (const Label& l : image.labels)
      if (!l.ignore && !table.lookup(l.className)) table.entries.emplace_back(l.className, l.className);
  for (const std::string& spec : o.maps) table.set(spec);

  std::vector<fusion::ExchangeImage> images;
  if (o.format == "coco") {
    nlohmann::json coco;
    try {
      coco = nlohmann::json::parse(readText(o.file));
    } catch (const nlohmann::json::parse_error& e) {
      throw std::runtime_error(o.file.string() + ": not JSON: " + e.what());
    }
    images = fusion::imagesFromCoco(coco, table, o.file.string());
  } else if (o.format == "cvat") {
    fusion::CvatLabels cvat = fusion::imagesFromCvat(readText(o.file), table, o.file.string());
    if (cvat.skippedShapes > 0)
      std::fprintf(stderr,
                   "dataset import: %s: %zu shapes other than boxes skipped (only boxes become labels)\n",
                   o.file.c_str(), cvat.skippedShapes);
    images = std::move(cvat.images);
  } else {
    images = fusion::readKittiLabelFiles(o.file, table);
  }
  const auto result = fusion::applyExchangeImages(o.dataset, current, images, o.allowUnmatched);
  for (const std::string& name : result.unmatched)
    std::fprintf(stderr, "dataset import: %s: image '%s' is no item of %s: skipped\n", o.file.c_str(),
                 name.c_str(), o.dataset.c_str());
  std::printf("import   %zu items relabelled, %zu labels, %zu images skipped <- %s (%s)\n", result.items,
              result.labels, result.unmatched.size(), o.file.c_str(), o.format.c_str());
  return 0;
}

int runFromLog(const DatasetOptions& o) {
  const sensor_logs::FromLogReport r = sensor_logs::datasetFromLog(o.log, o.out, o.fromLog);
  if (!r.damage.empty()) std::fprintf(stderr, "dataset from-log: %s: %s\n", o.log.c_str(), r.damage.c_str());
  std::printf("from-log %s: %ju stacks fused, %ju items written to %s (group %s)%s\n", o.log.c_str(),
              static_cast<std::uintmax_t>(r.stacks), static_cast<std::uintmax_t>(r.written), o.out.c_str(),
              r.group.c_str(), o.fromLog.images ? ", camera images in images/" : "");
  return r.written > 0 ? 0 : 3;
}

// Copies one item (every layer) into another data set, refusing to replace one there.
void copyItem(const fs::path& from, const DatasetEntry& entry, const fs::path& to,
              std::set<std::string>& taken) {
  if (!taken.insert(entry.id).second)
    throw std::runtime_error(from.string() + ": item '" + entry.id + "' is already in " + to.string() +
                             " (ids must be unique across the merged data sets)");
  writeDatasetItem(to, readDatasetItem(from, entry.id));
}

std::set<std::string> existingIds(const fs::path& dataset) {
  std::set<std::string> ids;
  if (fs::exists(dataset / "dataset.json"))
    for (const std::string& id : listDataset(dataset)) ids.insert(id);
  return ids;
}

int runMerge(const DatasetOptions& o) {
  std::set<std::string> taken = existingIds(o.out);
  for (const fs::path& in : o.inputs)
    if (fs::weakly_canonical(in) == fs::weakly_canonical(o.out))
      throw std::runtime_error(in.string() + ": is the output; merge into a new folder");
  std::size_t items = 0;
  for (const fs::path& in : o.inputs)
    for (const DatasetEntry& e : readDatasetManifest(in)) {
      copyItem(in, e, o.out, taken);
      ++items;
    }
  std::printf("merge    %zu items from %zu data sets -> %s\n", items, o.inputs.size(), o.out.c_str());
  return 0;
}

// The part an item goes to: its group (the log or KITTI folder it came from), or for --by drive the
// raw KITTI drive its folder's SOURCE.md names (fusedet/fusion/datasets/kitti_drives.h).
std::map<std::string, std::vector<DatasetEntry>> splitParts(const DatasetOptions& o) {
  if (o.by != "log" && o.by != "group" && o.by != "drive")
    throw std::runtime_error("--by '" + o.by + "': use log (the item's group) or drive (KITTI's raw drive)");
  std::map<std::string, fusion::KittiDriveMap> driveMaps;
  std::map<std::string, std::vector<DatasetEntry>> parts;
  for (const DatasetEntry& e : readDatasetManifest(o.dataset)) {
    if (o.by != "drive") {
      parts[e.group].push_back(e);
      continue;
    }
    if (!driveMaps.contains(e.group)) driveMaps[e.group] = fusion::readKittiDriveMap(o.kittiRoot / e.group);
    const std::string source = readDatasetItemLabels(o.dataset, e.id).stack.source;
    const std::string frame = source.substr(source.rfind('/') + 1);
    parts[driveMaps[e.group].driveOf(frame, e.group)].push_back(e);
  }
  return parts;
}

int runSplit(const DatasetOptions& o) {
  for (const auto& [group, entries] : splitParts(o)) {
    if (!isIdSegment(group))
      throw std::runtime_error("group '" + group + "' is no folder name (letters, digits, '_', '-', '.')");
    const fs::path to = o.out / group;
    std::set<std::string> taken = existingIds(to);
    for (const DatasetEntry& e : entries) copyItem(o.dataset, e, to, taken);
    std::printf("split    %s: %zu items -> %s\n", group.c_str(), entries.size(), to.c_str());
  }
  return 0;
}

const bool registered = registerCommand(
    "dataset", "Look at, merge and split data sets; import and export labels as CVAT, COCO or KITTI files",
    [](CLI::App& app) {
      auto o = std::make_shared<DatasetOptions>();
      app.require_subcommand(1);
      CLI::App* info = app.add_subcommand("info", "items, groups, reference sizes, labels per class, layers");
      info->add_option("DATASET", o->dataset, "a data set folder (docs/dataset-format.md)")
          ->required()
          ->check(CLI::ExistingDirectory);
      info->add_flag("--json", o->json, "one JSON object instead of text lines");

      CLI::App* fromLog = app.add_subcommand(
          "from-log", "data set items from a recorded sensor log, fused as fusedetd fuses it (no labels yet)");
      fromLog->add_option("LOG", o->log, "an MCAP sensor log with its rig (fusedet record, fusedet synth-log)")
          ->required()
          ->check(CLI::ExistingFile);
      fromLog->add_option("--out", o->out, "the data set to write (created, or added to)")->required();
      fromLog->add_option("--every", o->fromLog.every, "keep every n-th fused stack")->capture_default_str();
      fromLog->add_option("--stride-s", o->fromLog.strideSeconds,
                          "keep a stack only this many seconds after the last kept one (0: no limit)")
          ->capture_default_str();
      fromLog->add_option("--group", o->fromLog.group, "the items' group (default: the log's file name)");
      fromLog->add_flag("!--no-images", o->fromLog.images, "do not write images/<id>.png for labelling");

      CLI::App* exp =
          app.add_subcommand("export", "write the labels of every item as a labelling tool's file");
      exp->add_option("DATASET", o->dataset, "a data set folder")->required()->check(CLI::ExistingDirectory);
      exp->add_option("--format", o->format,
                      "cvat (CVAT for images 1.1 XML), coco (COCO JSON) or kitti (a folder of label_2 files)")
          ->required();
      exp->add_option("--out", o->out, "the file to write (kitti: the folder)")->required();

      CLI::App* imp =
          app.add_subcommand("import", "replace the labels of the items a labelling tool's file names");
      imp->add_option("DATASET", o->dataset, "a data set folder")->required()->check(CLI::ExistingDirectory);
      imp->add_option("FILE", o->file, "the file (kitti: the folder of <item id>.txt files)")
          ->required()
          ->check(CLI::ExistingPath);
      imp->add_option("--format", o->format, "cvat, coco or kitti")->required();
      imp->add_option("--map", o->maps,
                      "NAME=CLASS: the tool's class NAME is project class CLASS ('ignore': an ignore "
                      "region); repeatable");
      imp->add_flag("--skip-unknown-images", o->allowUnmatched,
                    "skip images that name no item (default: refuse the file)");

      CLI::App* merge = app.add_subcommand("merge", "copy the items of several data sets into one");
      merge->add_option("DATASETS", o->inputs, "data set folders")->required()->check(CLI::ExistingDirectory);
      merge->add_option("--out", o->out, "the data set to write (new, or one whose ids do not clash)")
          ->required();

      CLI::App* split = app.add_subcommand("split", "one data set per log (the item's group) or per raw KITTI drive, under a folder");
      split->add_option("DATASET", o->dataset, "a data set folder")
          ->required()
          ->check(CLI::ExistingDirectory);
      split
          ->add_option("--by", o->by,
                       "log: the item's group (the log or KITTI folder it came from); drive: the raw KITTI drive "
                       "its folder's SOURCE.md names (object-benchmark folders mix drives)")
          ->capture_default_str();
      split->add_option("--kitti-root", o->kittiRoot, "--by drive: where the KITTI folders (and their SOURCE.md) are")
          ->capture_default_str();
      split->add_option("--out", o->out, "folder for OUT/<log or drive>/")->required();

      app.footer(
          "from-log replays the log through fusedetd's own pipeline (decoders, sweep assembly, pairing, fusion) with\n"
          "the rig and calibration the log carries; each kept stack becomes item <group>/<stack id> and its camera\n"
          "image OUT/images/<group>/<stack id>.png, the name labelling files use (exit 3 when no stack was fused).\n"
          "Labelling files name each image <item id>.png (e.g. kitti_0009/000004.png); import finds the item "
          "by\n"
          "that name, or by its last part when only one item ends so, and refuses a file whose image size "
          "differs\n"
          "from the item's. Import replaces the labels of the items the file names and leaves every other "
          "item\n"
          "as it is; nothing is written when any image or class is refused.\n"
          "Classes: person/pedestrian -> person, bicycle/cyclist/bike -> bike, car -> car, van -> van; "
          "DontCare,\n"
          "ignore, Truck, Tram, Misc, Person_sitting -> ignore regions; a class the data set already has "
          "maps to\n"
          "itself; any other name is refused unless --map names it. Ignore regions travel as COCO iscrowd 1, "
          "a CVAT\n"
          "attribute ignore=true, and KITTI DontCare (or their own KITTI class). Occlusion and truncation "
          "travel as\n"
          "KITTI fields, CVAT attributes, and extra COCO annotation keys.\n"
          "Examples:\n"
          "  fusedet dataset from-log run.mcap --out data/robot --stride-s 2   # a stack every 2 s\n"
          "  fusedet dataset info data/kitti_set\n"
          "  fusedet dataset export data/kitti_set --format cvat --out labels.xml   # open in CVAT, correct\n"
          "  fusedet dataset import data/kitti_set labels-corrected.xml --format cvat\n"
          "  fusedet dataset export data/kitti_set --format coco --out instances.json\n"
          "  fusedet dataset import data/robot_set coco.json --format coco --map motorcycle=ignore\n"
          "  fusedet dataset merge data/a data/b --out data/ab\n"
          "  fusedet dataset split data/ab --by log --out data/per-log\n"
          "  fusedet dataset split data/kitti_set --by drive --out data/per-drive   # KITTI's raw drives\n"
          "Exit status: 0 done; 1 on errors ('fusedet dataset: error: ...'), which name the file and field.");
      return [o, info, fromLog, exp, imp, merge, split]() -> int {
        if (info->parsed()) return runInfo(*o);
        if (fromLog->parsed()) return runFromLog(*o);
        if (exp->parsed()) return runExport(*o);
        if (imp->parsed()) return runImport(*o);
        if (merge->parsed()) return runMerge(*o);
        if (split->parsed()) return runSplit(*o);
        return 2;
      };
    });

}  // namespace
}  // namespace fusedet::tools
