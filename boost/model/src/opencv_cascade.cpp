// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/opencv_cascade.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "xml_reader.h"

namespace fusedet::boosting {

namespace {

using xml::Element;

// OpenCV's load-time epsilon (cascadedetect: THRESHOLD_EPS).
constexpr float kThresholdEps = 1e-5f;

class Importer {
 public:
  Importer(std::string source, std::string layer) : source_(std::move(source)), layer_(std::move(layer)) {}

  Cascade run(std::string_view text) {
    std::unique_ptr<Element> root;
    try {
      root = xml::parse(text);
    } catch (const xml::ParseError& e) {
      throw std::runtime_error(source_ + ": " + e.what() + " (malformed or truncated XML)");
    }
    if (root->name != "opencv_storage") fail(*root, "root element is <" + root->name + ">, expected <opencv_storage>");
    if (root->children.empty()) fail(*root, "<opencv_storage> holds no cascade");
    const Element& c = *root->children.front();
    Cascade out;
    out.source = source_;
    out.normalization = Normalization::kOpenCvVariance;
    out.layers = {layer_};
    out.className = std::filesystem::path(source_).stem().string();
    if (c.attribute("type_id") == "opencv-haar-classifier" || c.child("size")) readOld(c, out);
    else readNew(c, out);
    try {
      out.validate();
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(e.what());
    }
    return out;
  }

 private:
  [[noreturn]] void fail(const Element& at, const std::string& what) const {
    throw std::runtime_error(source_ + ": line " + std::to_string(at.line) + ": " + what);
  }

  const Element& need(const Element& parent, std::string_view name) const {
    const Element* e = parent.child(name);
    if (!e) fail(parent, "<" + parent.name + "> lacks <" + std::string(name) + ">");
    return *e;
  }

  std::vector<double> numbers(const Element& e) const {
    std::vector<double> out;
    const std::string& t = e.text;
    const char* p = t.c_str();
    const char* end = p + t.size();
    while (p < end) {
      while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
      if (p >= end) break;
      char* stop = nullptr;
      errno = 0;
      const double v = std::strtod(p, &stop);
      if (stop == p || (stop < end && !std::isspace(static_cast<unsigned char>(*stop))))
        fail(e, "<" + e.name + "> holds '" + std::string(p, std::min<std::size_t>(20, std::size_t(end - p))) +
                    "', expected numbers");
      if (!std::isfinite(v)) fail(e, "<" + e.name + "> holds a non-finite number (NaN or infinity)");
      out.push_back(v);
      p = stop;
    }
    return out;
  }

  double number(const Element& e) const {
    const auto v = numbers(e);
    if (v.size() != 1) fail(e, "<" + e.name + "> must hold one number, found " + std::to_string(v.size()));
    return v[0];
  }

  int integer(const Element& e, double v) const {
    if (v != std::floor(v) || std::fabs(v) > 1e9) fail(e, "<" + e.name + "> holds " + std::to_string(v) + ", expected an integer");
    return static_cast<int>(v);
  }
  int integer(const Element& e) const { return integer(e, number(e)); }

  // Items of an OpenCV sequence: the <_> children.
  std::vector<const Element*> items(const Element& seq) const {
    std::vector<const Element*> out;
    for (const auto& ch : seq.children) {
      if (ch->name != "_") fail(*ch, "unexpected <" + ch->name + "> in <" + seq.name + ">");
      out.push_back(ch.get());
    }
    return out;
  }

  HaarFeature feature(const Element& f) const {
    HaarFeature h;
    const auto rects = items(need(f, "rects"));
    if (rects.size() < 2 || rects.size() > 3)
      fail(f, "feature has " + std::to_string(rects.size()) + " rectangles, expected 2 or 3");
    for (const Element* r : rects) {
      const auto v = numbers(*r);
      if (v.size() != 5) fail(*r, "rectangle must be 'x y width height weight', found " + std::to_string(v.size()) + " numbers");
      HaarRect q{integer(*r, v[0]), integer(*r, v[1]), integer(*r, v[2]), integer(*r, v[3]), static_cast<float>(v[4])};
      // OpenCV's converter drops a third rectangle of weight 0.
      if (h.count == 2 && std::fabs(q.weight) < 1.1920929e-07f) continue;
      h.rects[static_cast<std::size_t>(h.count++)] = q;
    }
    if (const Element* t = f.child("tilted")) {
      const int v = integer(*t);
      if (v != 0 && v != 1) fail(*t, "<tilted> must be 0 or 1");
      h.tilted = v == 1;
    }
    return h;
  }

  static double leaf(double v) {
    const auto f = static_cast<float>(v);
    return std::fabs(f) < kThresholdEps ? 0.0 : double(f);
  }
  static double stageThreshold(double t) { return double(static_cast<float>(t) - kThresholdEps); }

  void readNew(const Element& c, Cascade& out) const {
    if (const Element* st = c.child("stageType"); st && trim(st->text) != "BOOST")
      fail(*st, "stage type '" + trim(st->text) + "' is not supported (BOOST only)");
    const Element& ft = need(c, "featureType");
    if (trim(ft.text) != "HAAR") fail(ft, "feature type '" + trim(ft.text) + "' is not supported (HAAR only)");
    out.windowHeight = integer(need(c, "height"));
    out.windowWidth = integer(need(c, "width"));
    if (out.windowWidth <= 0 || out.windowHeight <= 0 || out.windowWidth > 4096 || out.windowHeight > 4096)
      fail(c, "window size " + std::to_string(out.windowWidth) + "x" + std::to_string(out.windowHeight) + " out of range");
    if (const Element* fp = c.child("featureParams"))
      if (const Element* mc = fp->child("maxCatCount"); mc && integer(*mc) != 0)
        fail(*mc, "categorical features (maxCatCount > 0) are not supported");
    const Element& stages = need(c, "stages");
    const auto stageItems = items(stages);
    if (const Element* sn = c.child("stageNum"); sn && integer(*sn) != int(stageItems.size()))
      fail(*sn, "stageNum says " + std::to_string(integer(*sn)) + " stages, <stages> holds " +
                    std::to_string(stageItems.size()));
    for (std::size_t s = 0; s < stageItems.size(); ++s) {
      const Element& se = *stageItems[s];
      Stage stage;
      std::vector<Tree> trees;
      stage.threshold = stageThreshold(number(need(se, "stageThreshold")));
      const auto weaks = items(need(se, "weakClassifiers"));
      if (const Element* mw = se.child("maxWeakCount"); mw && integer(*mw) != int(weaks.size()))
        fail(*mw, "stage " + std::to_string(s) + ": maxWeakCount says " + std::to_string(integer(*mw)) +
                      ", <weakClassifiers> holds " + std::to_string(weaks.size()));
      for (const Element* w : weaks) {
        const Element& nodesEl = need(*w, "internalNodes");
        const auto nodes = numbers(nodesEl);
        const auto leaves = numbers(need(*w, "leafValues"));
        if (nodes.size() % 4 != 0 || nodes.empty())
          fail(nodesEl, "internalNodes must hold 4 numbers per node, found " + std::to_string(nodes.size()));
        if (leaves.size() != nodes.size() / 4 + 1)
          fail(*w, "weak classifier has " + std::to_string(nodes.size() / 4) + " nodes but " +
                       std::to_string(leaves.size()) + " leaf values (expected nodes + 1)");
        Tree t;
        for (std::size_t n = 0; n < nodes.size(); n += 4) {
          const int fi = integer(nodesEl, nodes[n + 2]);
          if (fi < 0) fail(nodesEl, "negative feature index");
          t.nodes.push_back(TreeNode{fi, double(static_cast<float>(nodes[n + 3])), integer(nodesEl, nodes[n]),
                                     integer(nodesEl, nodes[n + 1])});
        }
        for (double v : leaves) t.leaves.push_back(leaf(v));
        trees.push_back(std::move(t));
      }
      out.treeStages.push_back(std::move(trees));
      out.stages.push_back(std::move(stage));
    }
    const auto feats = items(need(c, "features"));
    for (const Element* f : feats) out.haarFeatures.push_back(feature(*f));
    for (std::size_t s = 0; s < out.treeStages.size(); ++s)
      for (const Tree& t : out.treeStages[s])
        for (const TreeNode& n : t.nodes)
          if (static_cast<std::size_t>(n.feature) >= out.haarFeatures.size())
            fail(c, "stage " + std::to_string(s) + " uses feature " + std::to_string(n.feature) +
                        " but <features> holds " + std::to_string(out.haarFeatures.size()));
    toStumpsIfPossible(out);
  }

  // Cascades of one-split trees (leaves 0 and 1 as children) become stumps: the fast path.
  static void toStumpsIfPossible(Cascade& c) {
    for (const auto& st : c.treeStages)
      for (const Tree& t : st)
        if (t.nodes.size() != 1 || t.nodes[0].left != 0 || t.nodes[0].right != -1) return;
    for (std::size_t s = 0; s < c.treeStages.size(); ++s)
      for (const Tree& t : c.treeStages[s])
        c.stages[s].stumps.push_back(Stump{t.nodes[0].feature, t.nodes[0].threshold, t.leaves[0], t.leaves[1]});
    c.treeStages.clear();
  }

  void readOld(const Element& c, Cascade& out) const {
    const Element& size = need(c, "size");
    const auto wh = numbers(size);
    if (wh.size() != 2) fail(size, "<size> must be 'width height'");
    out.windowWidth = integer(size, wh[0]);
    out.windowHeight = integer(size, wh[1]);
    if (out.windowWidth <= 0 || out.windowHeight <= 0 || out.windowWidth > 4096 || out.windowHeight > 4096)
      fail(size, "window size out of range");
    for (const Element* se : items(need(c, "stages"))) {
      Stage stage;
      std::vector<Tree> trees;
      stage.threshold = stageThreshold(number(need(*se, "stage_threshold")));
      for (const Element* tree : items(need(*se, "trees"))) {
        // OpenCV's converter: leaves are numbered in order of appearance, a leaf child is -index.
        Tree t;
        const auto nodes = items(*tree);
        if (nodes.empty()) fail(*tree, "tree without nodes");
        for (const Element* n : nodes) {
          out.haarFeatures.push_back(feature(need(*n, "feature")));
          TreeNode node{int(out.haarFeatures.size()) - 1, double(static_cast<float>(number(need(*n, "threshold")))), 0, 0};
          auto child = [&](const char* val, const char* idx, int& to) {
            if (const Element* v = n->child(val)) {
              to = -static_cast<int>(t.leaves.size());
              t.leaves.push_back(leaf(number(*v)));
            } else if (const Element* i = n->child(idx)) {
              to = integer(*i);
            } else {
              fail(*n, std::string("node needs <") + val + "> or <" + idx + ">");
            }
          };
          child("left_val", "left_node", node.left);
          child("right_val", "right_node", node.right);
          t.nodes.push_back(node);
        }
        trees.push_back(std::move(t));
      }
      out.treeStages.push_back(std::move(trees));
      out.stages.push_back(std::move(stage));
    }
    toStumpsIfPossible(out);
  }

  static std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return {};
    return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
  }

  std::string source_, layer_;
};

}  // namespace

Cascade parseOpenCvCascade(std::string_view text, const std::string& source, const std::string& layer) {
  return Importer(source, layer).run(text);
}

Cascade loadOpenCvCascade(const std::filesystem::path& file, const std::string& layer) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parseOpenCvCascade(ss.str(), file.string(), layer);
}

}  // namespace fusedet::boosting
