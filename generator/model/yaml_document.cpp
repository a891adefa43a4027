#include "model/yaml_document.hpp"

#include "model/input_error.hpp"

#include <map>
#include <set>
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

}  // namespace

YAML::Node load_yaml_document(const std::string& text, const std::string& path) {
  std::vector<YAML::Node> documents;
  try {
    documents = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    throw InputError(where(path, e.mark), "", "YAML syntax error: " + e.msg);
  }
  if (documents.size() > 1)
    throw InputError(where(path, documents[1].Mark()), "",
                     "a second YAML document ('---') follows the model; expected exactly one document per file");
  YAML::Node root = documents.empty() ? YAML::Node() : documents.front();
  KeyChecker(text, path).check(root, "");
  return root;
}

}  // namespace hamel
