// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/network_record.h"

#include <algorithm>
#include <stdexcept>

namespace fusedet {
namespace {

std::vector<std::string_view> words(std::string_view text) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && text[i] == ' ') ++i;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ') ++i;
    if (i > start) out.push_back(text.substr(start, i - start));
  }
  return out;
}

bool positiveNumber(std::string_view t, int& v) {
  if (t.empty() || t.size() > 5) return false;
  v = 0;
  for (char c : t) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  return v > 0;
}

bool hexDigest(std::string_view t) {
  return t.size() == 64 && std::all_of(t.begin(), t.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

}  // namespace

std::string NetworkRecord::text() const {
  if (empty()) return "";
  std::string s = kind + " " + std::to_string(inputWidth) + "x" + std::to_string(inputHeight);
  for (std::size_t i = 0; i < fileNames.size(); ++i)
    s += " " + fileNames[i] + " sha256:" + (i < sha256.size() ? sha256[i] : std::string("?"));
  return s;
}

NetworkRecord parseNetworkRecord(std::string_view text) {
  const std::vector<std::string_view> w = words(text);
  NetworkRecord r;
  if (w.empty()) return r;
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("network '" + std::string(text) + "': " + why +
                                 " (expected KIND WxH FILE sha256:HEX [FILE sha256:HEX])");
  };
  if (w.size() < 4 || w.size() % 2 != 0) throw bad("wrong number of words");
  r.kind = std::string(w[0]);
  const std::size_t x = w[1].find('x');
  if (x == std::string_view::npos || !positiveNumber(w[1].substr(0, x), r.inputWidth) ||
      !positiveNumber(w[1].substr(x + 1), r.inputHeight))
    throw bad("'" + std::string(w[1]) + "' is not an input size WxH");
  for (std::size_t i = 2; i < w.size(); i += 2) {
    const std::string_view digest = w[i + 1];
    if (digest.substr(0, 7) != "sha256:" || !hexDigest(digest.substr(7)))
      throw bad("'" + std::string(digest) + "' is not sha256: and 64 lower-case hex digits");
    r.fileNames.emplace_back(w[i]);
    r.sha256.emplace_back(digest.substr(7));
  }
  return r;
}

bool isNetworkLayer(std::string_view layer) { return layer.substr(0, 7) == "neural_"; }

bool usesNetworkLayers(const std::vector<std::string>& layers) {
  return std::any_of(layers.begin(), layers.end(), [](const std::string& l) { return isNetworkLayer(l); });
}

void requireSameNetwork(const NetworkRecord& wanted, const std::string& modelName, const NetworkRecord& made,
                        const std::string& layersName) {
  if (wanted.empty())
    throw std::runtime_error(modelName + ": uses neural layers but records no network that made them; retrain it "
                             "(fusedet train records the network of its stacks' neural layers)");
  if (made.empty())
    throw std::runtime_error(modelName + ": needs neural layers of the network " + wanted.text() + ", but " +
                             layersName + " has no network (configure that network: kind, files, input size)");
  if (!(wanted == made))
    throw std::runtime_error(modelName + ": trained on neural layers of the network " + wanted.text() + ", but " +
                             layersName + " has the network " + made.text() +
                             "; configure the model's network (same files and input size) or retrain the model");
}

}  // namespace fusedet
