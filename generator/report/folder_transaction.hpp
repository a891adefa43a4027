// A folder of output files written as one transaction (hamel emit's package folder, `-o DIR`): the files are
// written and synced into a temporary sibling folder, which then takes the target's place in one atomic
// renameat2 (an exchange with the old folder, or a rename where there was none), so that the folder holds either
// the old files or the new ones, never a mix. A folder is replaced only if hamel wrote everything in it, as its
// manifest (`.hamel-manifest`: every file's name and content hash) proves; it is checked before the files are
// written and again around the exchange, so a file put into it meanwhile is neither lost nor overwritten.
// Single files go through report/atomic_file.hpp.
#pragma once

#include <string>
#include <vector>

namespace hamel {

/// One file of a folder: its name in the folder and its content.
struct FolderFile {
  std::string name, text;
};

/// The checks write_folder makes of `directory` before writing, for a refusal before any long work: a folder name,
/// and, if the folder exists, one an earlier write of the files `names` wrote. Throws InputError naming -o.
void check_folder_replaceable(const std::string& directory, const std::vector<std::string>& names);

/// Writes `files` and their manifest as the folder `directory`, atomically (see above). A folder that cannot be
/// replaced is an InputError naming -o; a failed write an OutputError (report/atomic_file.hpp). The temporary folder
/// is removed on failure, and on SIGINT, SIGTERM or SIGHUP (report/temporaries.hpp).
void write_folder(const std::string& directory, const std::vector<FolderFile>& files);

}  // namespace hamel
