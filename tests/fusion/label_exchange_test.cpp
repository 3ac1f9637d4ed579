// SPDX-License-Identifier: Apache-2.0
// Labels in and out of a data set as CVAT, COCO and KITTI files: round trips through each format,
// files written by hand the way the tools write them, and refusals that name the file and field.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/core.hpp>

#include "fusedet/core/dataset.h"
#include "fusedet/fusion/datasets/coco_labels.h"
#include "fusedet/fusion/datasets/cvat_labels.h"
#include "fusedet/fusion/datasets/kitti_label_files.h"
#include "fusedet/fusion/datasets/label_exchange.h"

namespace fusedet::fusion {
namespace {
namespace fs = std::filesystem;

Label label(const std::string& cls, double x, double y, double w, double h, bool ignore = false,
            int occlusion = 0, double truncation = 0) {
  Label l;
  l.className = cls;
  l.sourceClass = cls;
  l.box = Box{x, y, w, h};
  l.ignore = ignore;
  l.occlusion = occlusion;
  l.truncation = truncation;
  return l;
}

Label teacher(Label l) {
  l.origin = "teacher";
  return l;
}

// A data set of three 64x48 items in two groups, labelled with every kind of label.
fs::path makeDataset(const std::string& name) {
  const fs::path dir = fs::path(testing::TempDir()) / ("label_exchange_" + name);
  fs::remove_all(dir);
  const std::vector<std::pair<std::string, Labels>> items = {
      {"drive_a/000001",
       {label("car", 10.25, 5.5, 20, 12.75, false, 1, 0.25), label("person", 40, 8, 6, 18, false, 2),
        label("DontCare", 0, 30, 15, 10, true, -1, -1)}},
      {"drive_a/000002",
       {label("bike", 3, 4, 12.5, 9, false, 0, 0.5), label("Truck", 20, 20, 30, 20, true, 0),
        teacher(label("car", 33, 2, 20, 11.5))}},
      {"drive_b/000001", {}}};
  for (const auto& [id, labels] : items) {
    DatasetItem item;
    item.id = id;
    item.group = id.substr(0, id.find('/'));
    item.stack.setReferenceSize(64, 48);
    item.stack.set(Layer{"intensity", cv::Mat(48, 64, CV_8U, cv::Scalar(7)), {}});
    item.labels = labels;
    writeDatasetItem(dir, item);
  }
  return dir;
}

void clearLabels(const fs::path& dir) {
  for (const std::string& id : listDataset(dir)) writeDatasetItemLabels(dir, id, {});
}

std::vector<Labels> labelsOf(const fs::path& dir) {
  std::vector<Labels> out;
  for (const std::string& id : listDataset(dir)) out.push_back(readDatasetItemLabels(dir, id).labels);
  return out;
}

void expectSameLabels(const std::vector<Labels>& a, const std::vector<Labels>& b, double tolerance,
                      bool withOcclusionAndTruncation) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].size(), b[i].size()) << "item " << i;
    for (std::size_t k = 0; k < a[i].size(); ++k) {
      SCOPED_TRACE("item " + std::to_string(i) + " label " + std::to_string(k));
      EXPECT_EQ(a[i][k].className, b[i][k].className);
      EXPECT_EQ(a[i][k].ignore, b[i][k].ignore);
      if (withOcclusionAndTruncation) {
        EXPECT_EQ(a[i][k].origin, b[i][k].origin);
      }
      EXPECT_NEAR(a[i][k].box.x, b[i][k].box.x, tolerance);
      EXPECT_NEAR(a[i][k].box.y, b[i][k].box.y, tolerance);
      EXPECT_NEAR(a[i][k].box.w, b[i][k].box.w, tolerance);
      EXPECT_NEAR(a[i][k].box.h, b[i][k].box.h, tolerance);
      if (withOcclusionAndTruncation) {
        EXPECT_EQ(a[i][k].occlusion, b[i][k].occlusion);
        EXPECT_NEAR(a[i][k].truncation, b[i][k].truncation, 1e-3);
      }
    }
  }
}

TEST(LabelExchange, CocoRoundTripKeepsEveryLabel) {
  const fs::path dir = makeDataset("coco");
  const auto before = labelsOf(dir);
  const nlohmann::json coco = cocoFromImages(exchangeImages(dir));
  clearLabels(dir);
  const auto result = applyExchangeImages(dir, imagesFromCoco(coco, {}, "test.json"));
  EXPECT_EQ(result.items, 3u);
  EXPECT_EQ(result.labels, 6u);
  expectSameLabels(before, labelsOf(dir), 1e-9, true);
}

TEST(LabelExchange, CvatRoundTripKeepsEveryLabelToTwoDecimals) {
  const fs::path dir = makeDataset("cvat");
  const auto before = labelsOf(dir);
  const std::string xml = cvatFromImages(exchangeImages(dir), "task");
  clearLabels(dir);
  const CvatLabels cvat = imagesFromCvat(xml, {}, "test.xml");
  EXPECT_EQ(cvat.skippedShapes, 0u);
  applyExchangeImages(dir, cvat.images);
  expectSameLabels(before, labelsOf(dir), 0.005, true);
}

TEST(LabelExchange, KittiRoundTripKeepsEveryLabelToTwoDecimals) {
  const fs::path dir = makeDataset("kitti");
  const auto before = labelsOf(dir);
  const fs::path out = fs::path(testing::TempDir()) / "label_exchange_kitti_files";
  fs::remove_all(out);
  EXPECT_EQ(writeKittiLabelFiles(out, exchangeImages(dir)), 3u);
  EXPECT_TRUE(fs::exists(out / "drive_a" / "000002.txt"));
  clearLabels(dir);
  applyExchangeImages(dir, readKittiLabelFiles(out, {}));
  auto expected = before;  // KITTI files have no origin: every box reads back as a person's
  for (Labels& labels : expected)
    for (Label& l : labels) l.origin = "human";
  expectSameLabels(expected, labelsOf(dir), 0.005, true);
}

// A COCO file as COCO-style tools write it (hand-written here, not by our writer): category ids
// of COCO, a crowd region, an image the data set names by its last id segment only.
TEST(LabelExchange, ReadsACocoFileWrittenByHand) {
  const fs::path dir = makeDataset("coco_hand");
  const auto coco = nlohmann::json::parse(R"({
    "images": [{"id": 7, "file_name": "000002.png", "width": 64, "height": 48},
               {"id": 9, "file_name": "drive_a/000001.jpg", "width": 64, "height": 48}],
    "annotations": [
      {"id": 1, "image_id": 7, "category_id": 2, "bbox": [1.5, 2, 10, 20], "area": 200, "iscrowd": 0},
      {"id": 2, "image_id": 7, "category_id": 1, "bbox": [30, 10, 8, 16], "area": 128, "iscrowd": 1},
      {"id": 5, "image_id": 9, "category_id": 3, "bbox": [0, 0, 64, 48], "area": 3072, "iscrowd": 0}],
    "categories": [{"id": 1, "name": "person"}, {"id": 2, "name": "bicycle"}, {"id": 3, "name": "car"}]})");
  applyExchangeImages(dir, imagesFromCoco(coco, {}, "hand.json"));
  const Labels second = readDatasetItemLabels(dir, "drive_a/000002").labels;
  ASSERT_EQ(second.size(), 2u);
  EXPECT_EQ(second[0].className, "bike");
  EXPECT_EQ(second[0].sourceClass, "bicycle");
  EXPECT_FALSE(second[0].ignore);
  EXPECT_DOUBLE_EQ(second[0].box.x, 1.5);
  EXPECT_DOUBLE_EQ(second[0].box.h, 20);
  EXPECT_EQ(second[1].className, "person");
  EXPECT_TRUE(second[1].ignore);  // iscrowd
  const Labels first = readDatasetItemLabels(dir, "drive_a/000001").labels;
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].className, "car");
  EXPECT_DOUBLE_EQ(first[0].box.w, 64);
  EXPECT_TRUE(readDatasetItemLabels(dir, "drive_b/000001").labels.empty());  // not in the file: kept
}

// A CVAT for images 1.1 file as CVAT exports it (its documented layout, hand-written): corners,
// occluded flag, a polygon (skipped) and a tag (no shape).
TEST(LabelExchange, ReadsACvatFileWrittenByHand) {
  const fs::path dir = makeDataset("cvat_hand");
  const std::string xml = R"(<?xml version="1.0" encoding="utf-8"?>
<annotations>
  <version>1.1</version>
  <meta><task><id>3</id><name>robot</name></task></meta>
  <image id="0" name="drive_b/000001.png" width="64" height="48">
    <box label="Pedestrian" source="manual" occluded="1" xtl="12.00" ytl="4.50" xbr="20.00" ybr="40.25" z_order="0">
    </box>
    <polygon label="car" source="manual" occluded="0" points="1.0,2.0;5.0,2.0;5.0,9.0" z_order="0"></polygon>
    <tag label="night" source="manual"></tag>
    <box label="DontCare" source="manual" occluded="0" xtl="50" ytl="0" xbr="64" ybr="10" z_order="0"></box>
  </image>
</annotations>)";
  const CvatLabels cvat = imagesFromCvat(xml, {}, "hand.xml");
  EXPECT_EQ(cvat.skippedShapes, 1u);
  applyExchangeImages(dir, cvat.images);
  const Labels labels = readDatasetItemLabels(dir, "drive_b/000001").labels;
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].className, "person");
  EXPECT_EQ(labels[0].occlusion, 1);
  EXPECT_DOUBLE_EQ(labels[0].box.x, 12);
  EXPECT_DOUBLE_EQ(labels[0].box.h, 35.75);
  EXPECT_TRUE(labels[1].ignore);
  EXPECT_EQ(labels[1].className, "DontCare");
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(LabelExchange, RefusalsNameTheFileAndTheField) {
  const fs::path dir = makeDataset("refusals");
  const auto before = labelsOf(dir);
  auto coco = [](const std::string& annotations) {
    return nlohmann::json::parse(R"({"images": [{"id": 1, "file_name": "drive_b/000001.png", "width": 64,
      "height": 48}], "categories": [{"id": 1, "name": "person"}, {"id": 4, "name": "motorcycle"}],
      "annotations": [)" + annotations +
                                 "]}");
  };
  EXPECT_NE(errorOf([&] {
              imagesFromCoco(coco(R"({"id": 1, "image_id": 1, "category_id": 1, "bbox": [1, 2, "3", 4]})"),
                             {}, "a.json");
            }).find("a.json: annotations[0].bbox[2] must be a number"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              imagesFromCoco(coco(R"({"id": 1, "image_id": 2, "category_id": 1, "bbox": [1, 2, 3, 4]})"), {},
                             "a.json");
            }).find("annotations[0].image_id names no image"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              imagesFromCoco(coco(R"({"id": 1, "image_id": 1, "category_id": 1, "bbox": [1, 2, -3, 4]})"), {},
                             "a.json");
            }).find("negative width"),
            std::string::npos);
  // A class the table does not know is refused with the option that would take it.
  const std::string unknown = errorOf([&] {
    imagesFromCoco(coco(R"({"id": 1, "image_id": 1, "category_id": 4, "bbox": [1, 2, 3, 4]})"), {}, "a.json");
  });
  EXPECT_NE(unknown.find("class 'motorcycle' is not in the class table"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("--map 'motorcycle=CLASS'"), std::string::npos) << unknown;
  LabelClassTable table;
  table.set("motorcycle=ignore");
  const auto images = imagesFromCoco(
      coco(R"({"id": 1, "image_id": 1, "category_id": 4, "bbox": [1, 2, 3, 4]})"), table, "a.json");
  ASSERT_EQ(images.at(0).labels.size(), 1u);
  EXPECT_TRUE(images[0].labels[0].ignore);

  // A wrong image size, or an image no item has, changes nothing.
  std::vector<ExchangeImage> wrongSize = {
      ExchangeImage{"drive_a/000001.png", 64, 48, {}},
      ExchangeImage{"drive_b/000001.png", 128, 96, {label("car", 1, 1, 5, 5)}}};
  EXPECT_NE(errorOf([&] {
              applyExchangeImages(dir, wrongSize);
            }).find("is 128x96 but item 'drive_b/000001' is 64x48"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              applyExchangeImages(dir, {ExchangeImage{"nowhere.png", 64, 48, {}}});
            }).find("image 'nowhere.png' is no item"),
            std::string::npos);
  // "000001" ends two items' ids: ambiguous.
  EXPECT_NE(errorOf([&] {
              applyExchangeImages(dir, {ExchangeImage{"000001.png", 64, 48, {}}});
            }).find("matches several items"),
            std::string::npos);
  expectSameLabels(before, labelsOf(dir), 0, true);
  const auto skipped = applyExchangeImages(dir, {ExchangeImage{"nowhere.png", 64, 48, {}}}, true);
  EXPECT_EQ(skipped.unmatched, std::vector<std::string>{"nowhere.png"});

  EXPECT_NE(errorOf([&] {
              imagesFromCvat(
                  "<annotations><image name='x.png' width='64' height='48'><box label='car' xtl='1' "
                  "ytl='2' xbr='nan' ybr='4'/></image></annotations>",
                  {}, "b.xml");
            }).find("b.xml: image 'x.png' box 'car': xbr=\"nan\" is not a finite number"),
            std::string::npos);
  // Issue 37: finite corners whose width overflows to inf were accepted.
  EXPECT_NE(errorOf([&] {
              imagesFromCvat(
                  "<annotations><image name='x.png' width='64' height='48'><box label='car' xtl='-1e308' "
                  "ytl='2' xbr='1e308' ybr='4'/></image></annotations>",
                  {}, "b.xml");
            }).find("b.xml: image 'x.png' box 'car': xbr/ybr lie before xtl/ytl or the size is not finite"),
            std::string::npos);
  EXPECT_NE(errorOf([&] {
              imagesFromCvat("<annotations><track id='0' label='car'/></annotations>", {}, "b.xml");
            }).find("CVAT for video"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { imagesFromCvat("<annotations", {}, "b.xml"); }).find("b.xml: not XML"),
            std::string::npos);
}

}  // namespace
}  // namespace fusedet::fusion
