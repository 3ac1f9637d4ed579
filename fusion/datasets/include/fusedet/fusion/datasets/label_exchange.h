// SPDX-License-Identifier: Apache-2.0
#pragma once
// Labels in and out of a data set through the files labelling tools use (CVAT, COCO, KITTI): the
// format-neutral middle of `fusedet dataset import|export`. An image of a labelling file is a data
// set item: its name is the item id plus ".png" (what `exchangeImages` writes and the exported
// camera images are called), and the item's reference size is the image size.

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fusedet/core/label.h"

namespace fusedet::fusion {

// One image of a labelling file with its boxes (reference pixels, x/y = top-left corner).
struct ExchangeImage {
  std::string name;  // "kitti_0009/000004.png"
  int width = 0;     // 0 = the file does not say (KITTI label_2)
  int height = 0;
  Labels labels;
};

// The small table that maps the class names labelling tools use onto project classes.
// Names compare case-insensitively; a project class "" makes the name an ignore region.
struct LabelClassTable {
  std::vector<std::pair<std::string, std::string>> entries = {{"person", "person"},  {"pedestrian", "person"},
                                                              {"bicycle", "bike"},   {"cyclist", "bike"},
                                                              {"bike", "bike"},      {"car", "car"},
                                                              {"van", "van"},        {"dontcare", ""},
                                                              {"ignore", ""},        {"truck", ""},
                                                              {"tram", ""},          {"misc", ""},
                                                              {"person_sitting", ""}};
  // The project class of `name` ("" = ignore region), or nullopt when the table does not know it.
  std::optional<std::string> lookup(const std::string& name) const;
  // "NAME=CLASS" (CLASS "ignore" or empty: an ignore region) adds or replaces an entry; throws
  // std::invalid_argument naming the spec when it has no '='.
  void set(const std::string& spec);
};

// A label read from a file: its class through the table (unknown names throw
// std::runtime_error naming `where`, the name, and the --map option that would accept it).
Label exchangeLabel(const LabelClassTable& table, const std::string& name, const std::string& where);

// The image name of an item and back: "kitti/000042" <-> "kitti/000042.png". itemIdOf drops the
// extension and a leading "./"; any other name is taken as it is.
std::string imageNameOf(const std::string& itemId);
std::string itemIdOf(const std::string& imageName);

// Every item of a data set as an exchange image (labels and reference size; no pixels decoded).
std::vector<ExchangeImage> exchangeImages(const std::filesystem::path& datasetDir);

struct ApplyLabelsResult {
  std::size_t items = 0;               // items whose labels were replaced
  std::size_t labels = 0;              // labels written
  std::vector<std::string> unmatched;  // image names with no item (only when allowed)
};
// Replaces the labels of the item each image names (items the file does not name keep theirs).
// An image whose name matches no item id throws, naming it, unless `allowUnmatched`; a name
// without folders also matches a unique item whose last id segment it is. An image whose stated
// size differs from the item's reference size throws (boxes would land in the wrong pixels).
ApplyLabelsResult applyExchangeImages(const std::filesystem::path& datasetDir,
                                      const std::vector<ExchangeImage>& images, bool allowUnmatched = false);
// The same with the data set's items as exchangeImages(datasetDir) gave them (`current`), for a
// caller that has read them already: no item's labels are read twice.
ApplyLabelsResult applyExchangeImages(const std::filesystem::path& datasetDir, const std::vector<ExchangeImage>& current,
                                      const std::vector<ExchangeImage>& images, bool allowUnmatched);

}  // namespace fusedet::fusion
