// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/cvat_labels.h"

#include <tinyxml2.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <set>
#include <stdexcept>

#include "fusedet/fusion/datasets/box_corners.h"

namespace fusedet::fusion {

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw std::runtime_error(file + ": " + what);
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);  // CVAT writes two decimals
  return buf;
}

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  return out;
}

double attributeNumber(const std::string& file, const tinyxml2::XMLElement* e, const char* name,
                       const std::string& where) {
  const char* text = e->Attribute(name);
  if (!text) fail(file, where + " has no " + name);
  double v = 0;
  const char* end = text + std::strlen(text);
  const auto [ptr, ec] = std::from_chars(text, end, v);
  if (ec != std::errc() || ptr != end || !std::isfinite(v))
    fail(file, where + ": " + name + "=\"" + text + "\" is not a finite number");
  return v;
}

int positiveInt(const std::string& file, const tinyxml2::XMLElement* e, const char* name,
                const std::string& where) {
  const double v = attributeNumber(file, e, name, where);
  if (v != std::floor(v) || v < 1 || v > (1 << 16))
    fail(file, where + ": " + name + " must be an integer 1..65536");
  return static_cast<int>(v);
}

}  // namespace

std::string cvatFromImages(const std::vector<ExchangeImage>& images, const std::string& taskName) {
  std::set<std::string> labelNames;
  for (const ExchangeImage& image : images)
    for (const Label& l : image.labels) labelNames.insert(l.className);
  std::string xml = "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<annotations>\n  <version>1.1</version>\n";
  xml += "  <meta>\n    <task>\n      <name>" + escape(taskName) + "</name>\n      <size>" +
         std::to_string(images.size()) + "</size>\n      <mode>annotation</mode>\n      <labels>\n";
  for (const std::string& name : labelNames)
    xml +=
        "        <label>\n          <name>" + escape(name) +
        "</name>\n          <type>rectangle</type>\n          <attributes>\n"
        "            <attribute><name>occlusion</name><mutable>False</mutable><input_type>select</input_type>"
        "<default_value>0</default_value><values>0\n1\n2\n3\n-1</values></attribute>\n"
        "            "
        "<attribute><name>truncation</name><mutable>False</mutable><input_type>number</input_type>"
        "<default_value>0</default_value><values>0\n2\n0.01</values></attribute>\n"
        "            <attribute><name>ignore</name><mutable>False</mutable><input_type>checkbox</input_type>"
        "<default_value>false</default_value><values>false</values></attribute>\n"
        "          </attributes>\n        </label>\n";
  xml += "      </labels>\n    </task>\n  </meta>\n";
  for (std::size_t i = 0; i < images.size(); ++i) {
    const ExchangeImage& image = images[i];
    xml += "  <image id=\"" + std::to_string(i) + "\" name=\"" + escape(image.name) + "\" width=\"" +
           std::to_string(image.width) + "\" height=\"" + std::to_string(image.height) + "\">\n";
    for (const Label& l : image.labels) {
      char trunc[32];
      std::snprintf(trunc, sizeof trunc, "%.4g", l.truncation);
      xml += "    <box label=\"" + escape(l.className) + "\" source=\"" + (l.origin == "teacher" ? "auto" : "manual") + "\" occluded=\"" +
             (l.occlusion >= 1 ? "1" : "0") + "\" xtl=\"" + number(l.box.x) + "\" ytl=\"" + number(l.box.y) +
             "\" xbr=\"" + number(l.box.x + l.box.w) + "\" ybr=\"" + number(l.box.y + l.box.h) +
             "\" z_order=\"0\">\n      <attribute name=\"occlusion\">" + std::to_string(l.occlusion) +
             "</attribute>\n      <attribute name=\"truncation\">" + trunc +
             "</attribute>\n      <attribute name=\"ignore\">" + (l.ignore ? "true" : "false") +
             "</attribute>\n    </box>\n";
    }
    xml += "  </image>\n";
  }
  xml += "</annotations>\n";
  return xml;
}

CvatLabels imagesFromCvat(const std::string& xml, const LabelClassTable& table, const std::string& file) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS)
    fail(file, std::string("not XML: ") + (doc.ErrorStr() ? doc.ErrorStr() : "parse error"));
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (!root || std::string(root->Name()) != "annotations")
    fail(file, "not a CVAT file (no <annotations> root)");
  if (const auto* version = root->FirstChildElement("version");
      version && version->GetText() && std::string(version->GetText()) != "1.1")
    fail(file, std::string("CVAT format version ") + version->GetText() +
                   ": this reader knows 1.1 (CVAT for images 1.1)");
  if (root->FirstChildElement("track"))
    fail(file,
         "holds <track> elements: that is \"CVAT for video\"; export the task as \"CVAT for images 1.1\"");

  CvatLabels out;
  std::set<std::string> names;
  for (const auto* image = root->FirstChildElement("image"); image;
       image = image->NextSiblingElement("image")) {
    const char* name = image->Attribute("name");
    if (!name || !*name) fail(file, "an <image> has no name");
    const std::string where = std::string("image '") + name + "'";
    if (!names.insert(name).second) fail(file, where + " appears twice");
    ExchangeImage ex{
        name, positiveInt(file, image, "width", where), positiveInt(file, image, "height", where), {}};
    for (const auto* shape = image->FirstChildElement(); shape; shape = shape->NextSiblingElement()) {
      if (std::string(shape->Name()) != "box") {
        if (std::string(shape->Name()) != "tag") ++out.skippedShapes;
        continue;
      }
      const char* label = shape->Attribute("label");
      if (!label) fail(file, where + ": a <box> has no label");
      const std::string boxWhere = where + " box '" + label + "'";
      Label l = exchangeLabel(table, label, file + ": " + boxWhere);
      const double xtl = attributeNumber(file, shape, "xtl", boxWhere),
                   ytl = attributeNumber(file, shape, "ytl", boxWhere);
      const double xbr = attributeNumber(file, shape, "xbr", boxWhere),
                   ybr = attributeNumber(file, shape, "ybr", boxWhere);
      const std::optional<Box> box = boxFromCorners(xtl, ytl, xbr, ybr);
      if (!box) fail(file, boxWhere + ": xbr/ybr lie before xtl/ytl or the size is not finite");
      l.box = *box;
      // CVAT marks boxes a model drew "auto"; one a person drew or corrected is "manual"/"semi-auto".
      if (const char* source = shape->Attribute("source")) l.origin = std::string(source) == "auto" ? "teacher" : "human";
      if (const char* occluded = shape->Attribute("occluded"))
        l.occlusion = std::string(occluded) == "1" ? 1 : 0;
      for (const auto* a = shape->FirstChildElement("attribute"); a; a = a->NextSiblingElement("attribute")) {
        const std::string key = a->Attribute("name") ? a->Attribute("name") : "";
        const std::string value = a->GetText() ? a->GetText() : "";
        if (key == "ignore") {
          if (value != "true" && value != "false")
            fail(file, boxWhere + ": attribute ignore must be true or false");
          if (value == "true") l.ignore = true;
        } else if (key == "occlusion" || key == "truncation") {
          double v = 0;
          const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
          if (ec != std::errc() || ptr != value.data() + value.size() || !std::isfinite(v))
            fail(file, boxWhere + ": attribute " + key + " '" + value + "' is not a number");
          if (key == "truncation") {
            l.truncation = v;
          } else {
            if (v != std::floor(v) || v < -1 || v > 3)
              fail(file, boxWhere + ": occlusion must be an integer -1..3");
            l.occlusion = static_cast<int>(v);
          }
        }
      }
      ex.labels.push_back(std::move(l));
    }
    out.images.push_back(std::move(ex));
  }
  return out;
}

}  // namespace fusedet::fusion
