#include "model/yaml_document.hpp"

#include "model/input_error.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace hamel {

namespace {

SourceLocation where(const std::string& path, const YAML::Mark& m) {
  return {path, m.line >= 0 ? m.line + 1 : 0, m.column >= 0 ? m.column + 1 : 0};
}

// Walks every mapping once. Aliases share the node of their anchor, so nodes already seen (same
// position in the text) are skipped: nested aliases cannot make the walk exponential. The depth is
// bounded by yaml-cpp's own nesting limit.
class KeyChecker {
 public:
  KeyChecker(const std::string& text, const std::string& path) : text_(text), path_(path) {}

  void check(const YAML::Node& node, const std::string& context) {
    if (node.IsScalar()) check_closed(node, context);
    if (!node.IsMap() && !node.IsSequence()) return;
    if (!seen_.insert(node.Mark().pos).second) return;
    if (node.IsSequence()) {
      for (std::size_t i = 0; i < node.size(); ++i) check(node[i], context + "[" + std::to_string(i) + "]");
      return;
    }
    std::map<std::string, YAML::Mark> keys;
    for (const auto& kv : node) {
      const YAML::Node& key = kv.first;
      if (!key.IsScalar() || key.Scalar().empty())
        throw InputError(where(path_, key.Mark()), context,
                         "expected a plain name as key, got " + std::string(key.IsSequence() ? "a list"
                                                                            : key.IsMap()    ? "a map"
                                                                                             : "an empty key"));
      const std::string name = key.Scalar();
      check_closed(key, context);
      const std::string full = context.empty() ? name : context + "." + name;
      auto [it, inserted] = keys.emplace(name, key.Mark());
      if (!inserted)
        throw InputError(where(path_, key.Mark()), full,
                         "key given twice in the same mapping (first at line " + std::to_string(it->second.line + 1) +
                             "); remove one of them");
      check(kv.second, full);
    }
  }

 private:
  // yaml-cpp 0.7 accepts a quoted scalar that is never closed when the file ends inside it, taking the
  // rest of the file as its text. A plain scalar cannot start with a quote, so a scalar whose text
  // starts with one is quoted and must have its closing quote.
  void check_closed(const YAML::Node& scalar, const std::string& context) const {
    const int pos = scalar.Mark().pos;
    if (pos < 0 || static_cast<std::size_t>(pos) >= text_.size()) return;
    const char quote_char = text_[static_cast<std::size_t>(pos)];
    if (quote_char != '"' && quote_char != '\'') return;
    for (std::size_t i = static_cast<std::size_t>(pos) + 1; i < text_.size(); ++i) {
      if (quote_char == '"' && text_[i] == '\\') {
        ++i;  // an escaped character
      } else if (text_[i] == quote_char) {
        if (quote_char == '\'' && i + 1 < text_.size() && text_[i + 1] == '\'') {
          ++i;  // '' is a quote inside single quotes
        } else {
          return;
        }
      }
    }
    throw InputError(where(path_, scalar.Mark()), context,
                     std::string("YAML syntax error: the quoted text starting here is never closed; expected a "
                                 "closing ") +
                         quote_char);
  }

  const std::string& text_;
  std::string path_;
  std::set<int> seen_;
};

// Records where the document it is handed starts and whether it holds anything but a lone null.
class DocumentProbe : public YAML::EventHandler {
 public:
  YAML::Mark start;
  bool content = false;
  void OnDocumentStart(const YAML::Mark& mark) override { start = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override { content = true; }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override { content = true; }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    content = true;
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    content = true;
  }
  void OnMapEnd() override {}
};

// Throws if a document with content follows the first one. yaml-cpp 0.7 reports endless empty documents
// for some malformed input (a stray ',' at the top level; found by tests/fuzz: YAML::LoadAll never
// returns and exhausts memory there), so at most one probe per line of text is made.
void check_single_document(const std::string& text, const std::string& path) {
  // A second document starts after a marker at the start of a line ("---" or "..."); without one the text holds a
  // single document, and the second parse, as long as YAML::Load's, is saved (half the time of loading a large
  // model, such as an imported chain of 10 000 links).
  bool marker = false;
  for (std::size_t line = 0; line < text.size() && !marker;) {
    marker = text.compare(line, 3, "---") == 0 || text.compare(line, 3, "...") == 0;
    const std::size_t next = text.find('\n', line);
    line = next == std::string::npos ? text.size() : next + 1;
  }
  if (!marker) return;
  std::istringstream in(text);
  YAML::Parser parser(in);
  DocumentProbe first;
  if (!parser.HandleNextDocument(first)) return;
  const std::size_t probes = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 2;
  for (std::size_t i = 0; i < probes; ++i) {
    DocumentProbe next;
    if (!parser.HandleNextDocument(next)) return;
    if (next.content)
      throw InputError(where(path, next.start), "",
                       "a second YAML document ('---') follows the model; expected exactly one document per file");
  }
}

}  // namespace

YAML::Node load_yaml_document(const std::string& text, const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
    check_single_document(text, path);
  } catch (const YAML::Exception& e) {
    throw InputError(where(path, e.mark), "", "YAML syntax error: " + e.msg);
  }
  KeyChecker(text, path).check(root, "");
  return root;
}

}  // namespace hamel
