// Reading a model file's YAML text into one document, with the checks yaml-cpp does not make: exactly
// one document, no key given twice in a mapping, and every key a plain scalar.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

namespace hamel {

/// Parses `text` (named `path` in messages). Throws InputError at the offending line and column for a
/// YAML syntax error, a second document ("---") whose content would otherwise be ignored, a key that
/// appears twice in one mapping (yaml-cpp would silently keep one of them), or a key that is not a
/// plain scalar (a list or map used as a key, or an empty key).
YAML::Node load_yaml_document(const std::string& text, const std::string& path);

}  // namespace hamel
