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

/// Model and scene files are small text: larger files, devices (/dev/zero), pipes and folders are refused
/// before anything is read (docs/errors.md, "Limits").
constexpr std::size_t kMaxInputFileBytes = 1 << 20;

/// The text of a model or scene file (`what` names it in messages); InputError naming `path` when it is not
/// a regular file, larger than kMaxInputFileBytes or cannot be opened.
std::string read_input_file(const std::string& path, const std::string& what);

}  // namespace hamel
