// Output files appear whole or not at all: the text is written to a temporary file next to the target and
// renamed over it, so an interrupted or failed run never leaves a half-written file behind.
#pragma once

#include <string>

namespace hamel {

/// Writes `content` to `path` atomically; throws InputError (exit status 2) naming the path on failure.
void write_file_atomically(const std::string& path, const std::string& content);

}  // namespace hamel
