// SPDX-License-Identifier: Apache-2.0
#include "xml_reader.h"

#include <cctype>
#include <cstring>

namespace fusedet::boosting::xml {

const Element* Element::child(std::string_view childName) const {
  for (const auto& c : children)
    if (c->name == childName) return c.get();
  return nullptr;
}

std::string Element::attribute(std::string_view attrName) const {
  for (const auto& [k, v] : attributes)
    if (k == attrName) return v;
  return {};
}

namespace {

constexpr int kMaxDepth = 64;  // OpenCV cascades nest 6 deep; garbage must not recurse unbounded

class Parser {
 public:
  explicit Parser(std::string_view t) : t_(t) {}

  std::unique_ptr<Element> document() {
    skipMisc();
    if (eof()) fail("no root element");
    auto root = element(0);
    skipMisc();
    if (!eof()) fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw ParseError(line_, what); }
  bool eof() const { return p_ >= t_.size(); }
  char peek() const { return eof() ? '\0' : t_[p_]; }
  bool startsWith(std::string_view s) const { return t_.substr(p_, s.size()) == s; }
  void advance(std::size_t n = 1) {
    for (std::size_t i = 0; i < n && !eof(); ++i, ++p_)
      if (t_[p_] == '\n') ++line_;
  }
  void skipSpace() {
    while (!eof() && std::isspace(static_cast<unsigned char>(peek()))) advance();
  }
  void skipUntil(std::string_view end, const char* what) {
    const std::size_t at = t_.find(end, p_);
    if (at == std::string_view::npos) fail(std::string("unterminated ") + what);
    advance(at + end.size() - p_);
  }
  // Whitespace, comments, processing instructions and a DOCTYPE between elements.
  void skipMisc() {
    for (;;) {
      skipSpace();
      if (startsWith("<!--")) skipUntil("-->", "comment");
      else if (startsWith("<?")) skipUntil("?>", "processing instruction");
      else if (startsWith("<!DOCTYPE")) skipUntil(">", "DOCTYPE");
      else return;
    }
  }
  static bool nameChar(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == ':';
  }
  std::string name() {
    const std::size_t start = p_;
    while (!eof() && nameChar(peek())) advance();
    if (p_ == start) fail("expected a name");
    return std::string(t_.substr(start, p_ - start));
  }
  void appendDecoded(std::string_view raw, std::string& out) {
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] != '&') {
        out += raw[i];
        continue;
      }
      static constexpr std::pair<const char*, char> kEntities[] = {
          {"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'}, {"&quot;", '"'}, {"&apos;", '\''}};
      bool known = false;
      for (const auto& [ent, ch] : kEntities) {
        if (raw.substr(i, std::strlen(ent)) == ent) {
          out += ch;
          i += std::strlen(ent) - 1;
          known = true;
          break;
        }
      }
      if (!known) fail("unknown entity");
    }
  }

  std::unique_ptr<Element> element(int depth) {
    if (depth > kMaxDepth) fail("elements nested deeper than " + std::to_string(kMaxDepth));
    if (peek() != '<') fail("expected '<'");
    auto e = std::make_unique<Element>();
    e->line = line_;
    advance();
    e->name = name();
    for (;;) {
      skipSpace();
      if (startsWith("/>")) {
        advance(2);
        return e;
      }
      if (peek() == '>') {
        advance();
        break;
      }
      if (eof()) fail("unterminated start tag <" + e->name + ">");
      std::string key = name();
      skipSpace();
      if (peek() != '=') fail("expected '=' after attribute " + key);
      advance();
      skipSpace();
      const char q = peek();
      if (q != '"' && q != '\'') fail("attribute " + key + " value must be quoted");
      advance();
      const std::size_t end = t_.find(q, p_);
      if (end == std::string_view::npos) fail("unterminated attribute " + key);
      std::string value;
      appendDecoded(t_.substr(p_, end - p_), value);
      advance(end + 1 - p_);
      e->attributes.emplace_back(std::move(key), std::move(value));
    }
    // Content: text, comments, children, until the matching end tag.
    for (;;) {
      if (eof()) fail("missing </" + e->name + "> (element opened on line " + std::to_string(e->line) + ")");
      if (startsWith("</")) {
        advance(2);
        const std::string closing = name();
        if (closing != e->name)
          fail("</" + closing + "> closes <" + e->name + "> opened on line " + std::to_string(e->line));
        skipSpace();
        if (peek() != '>') fail("expected '>' after </" + closing);
        advance();
        return e;
      }
      if (startsWith("<!--")) {
        skipUntil("-->", "comment");
      } else if (startsWith("<![CDATA[")) {
        advance(9);
        const std::size_t end = t_.find("]]>", p_);
        if (end == std::string_view::npos) fail("unterminated CDATA");
        e->text.append(t_.substr(p_, end - p_));
        advance(end + 3 - p_);
      } else if (startsWith("<?")) {
        skipUntil("?>", "processing instruction");
      } else if (peek() == '<') {
        e->children.push_back(element(depth + 1));
      } else {
        const std::size_t start = p_;
        while (!eof() && peek() != '<') advance();
        appendDecoded(t_.substr(start, p_ - start), e->text);
      }
    }
  }

  std::string_view t_;
  std::size_t p_ = 0;
  int line_ = 1;
};

}  // namespace

std::unique_ptr<Element> parse(std::string_view text) { return Parser(text).document(); }

}  // namespace fusedet::boosting::xml
