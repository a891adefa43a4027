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
  explicit KeyChecker(const std::string& path) : path_(path) {}

  void check(const YAML::Node& node, const std::string& context) {
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
  KeyChecker(path).check(root, "");
  return root;
}

}  // namespace hamel
