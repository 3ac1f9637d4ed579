// SPDX-License-Identifier: Apache-2.0
#pragma once
// A small, strict reader for the XML subset OpenCV's FileStorage writes (elements, attributes,
// text, comments, the <?xml ?> declaration, the five predefined entities). Bounded nesting depth;
// every error names the line. Internal to boost/: only the OpenCV cascade importer uses it.

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace fusedet::boosting::xml {

struct Element {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::string text;  // concatenated character data directly inside this element
  std::vector<std::unique_ptr<Element>> children;
  int line = 0;

  const Element* child(std::string_view childName) const;  // first child of that name or null
  std::string attribute(std::string_view attrName) const;  // "" when absent
};

class ParseError : public std::runtime_error {
 public:
  ParseError(int line, const std::string& what)
      : std::runtime_error("line " + std::to_string(line) + ": " + what), line_(line) {}
  int line() const { return line_; }

 private:
  int line_;
};

// Parses a whole document and returns its root element. Throws ParseError.
std::unique_ptr<Element> parse(std::string_view text);

}  // namespace fusedet::boosting::xml
