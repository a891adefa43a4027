#include "report/atomic_file.hpp"

#include <filesystem>
#include <fstream>
#include <random>
#include "model/input_error.hpp"

namespace hamel {

void write_file_atomically(const std::string& path, const std::string& content) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path staging = target.string() + ".tmp-" + std::to_string(std::random_device{}());
  {
    std::ofstream out(staging, std::ios::binary);
    out << content;
    out.flush();
    if (!out) {
      std::error_code ignored;
      fs::remove(staging, ignored);
      throw InputError("cannot write " + path);
    }
  }
  std::error_code ec;
  fs::rename(staging, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(staging, ignored);
    throw InputError("cannot write " + path + ": " + ec.message());
  }
}

}  // namespace hamel
