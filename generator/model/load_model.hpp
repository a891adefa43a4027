// Reading a model file (schema 1, YAML) into a Model, with errors that name file:line:column and key.
#pragma once

#include "model/model.hpp"

#include <string>

namespace hamel {

/// Loads and validates the model file at `path`. Throws InputError on any problem in the file.
Model load_model(const std::string& path);

/// Same, from text already read; `path` is used in messages and in the Model's provenance.
Model load_model_from_text(const std::string& text, const std::string& path);

/// FNV-1a 64-bit hash of `bytes`, as 16 hex digits (provenance stamps, not security).
std::string content_hash(const std::string& bytes);

}  // namespace hamel
