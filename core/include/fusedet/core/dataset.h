// SPDX-License-Identifier: Apache-2.0
#pragma once
// The project's data set format: a directory of layer stacks + labels that fusion writes (KITTI
// import, recorded logs) and boost reads (training, evaluation, experiments). Files are ones
// common tools open: one PNG per layer (8- or 16-bit, float layers quantised with the scale and
// offset stated in a JSON sidecar), masks as 8-bit PNG, labels in JSON. Spec: docs/dataset-format.md.
//
//   DATASET/dataset.json                 manifest: item ids and groups, in frame order per group
//   DATASET/items/<id>/item.json         sidecar: reference size, stamp, labels, layer table
//   DATASET/items/<id>/<layer>.png       one layer
//   DATASET/items/<id>/<layer>.valid.png its validity mask (only layers that have one)

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusedet/core/label.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet {

// Any problem reading or writing a data set; the message names the file and the problem.
class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DatasetItem {
  std::string id;     // unique in the data set, e.g. "kitti/000042": '/'-separated [A-Za-z0-9_.-]
  std::string group;  // drive / sequence the item belongs to; split train/test by group
  LayerStack stack;   // layers, reference size, stamp, source; stack.id is kept too
  Labels labels;      // boxes in the stack's reference pixels
};

// Whether `segment` can be one '/'-separated part of an item id, so also a folder name:
// [A-Za-z0-9_.-]+, neither "." nor "..".
bool isIdSegment(const std::string& segment);
// `name` (a file stem, a group) as an id segment: every other character becomes '_'; what is
// still none ("", ".", "..") becomes `fallback`.
std::string toIdSegment(std::string name, const std::string& fallback);

struct DatasetEntry {
  std::string id;
  std::string group;
};

// Manifest of a data set, in the order items were first written (= frame order within a group).
// Throws DatasetError if dataset.json is missing or malformed.
std::vector<DatasetEntry> readDatasetManifest(const std::filesystem::path& datasetDir);
// Just the ids of readDatasetManifest().
std::vector<std::string> listDataset(const std::filesystem::path& datasetDir);

// Writes (or replaces) one item and records it in the manifest (creating the data set directory
// and manifest if needed). Float layers are quantised to 16 bit: see docs/dataset-format.md for
// the default quantum per layer. Not safe against two writers of the same data set at once.
void writeDatasetItem(const std::filesystem::path& datasetDir, const DatasetItem& item);

// Reads one item. `layers` selects the layers to load (empty = all), so a trainer can hold many
// stacks with only the layers it uses; a requested layer the item lacks is an error. Strict:
// anything missing, malformed, truncated or inconsistent throws DatasetError naming the file.
DatasetItem readDatasetItem(const std::filesystem::path& datasetDir, const std::string& id,
                            const std::vector<std::string>& layers = {});
// Labels (and group) only, without decoding any image; `stack` is left empty except its reference
// size, stamp, id and source.
DatasetItem readDatasetItemLabels(const std::filesystem::path& datasetDir, const std::string& id);
// Replaces one item's labels and nothing else (no image is decoded or written). Throws DatasetError
// naming the file when the item is missing or malformed, or a label box is not finite.
void writeDatasetItemLabels(const std::filesystem::path& datasetDir, const std::string& id, const Labels& labels);

}  // namespace fusedet
