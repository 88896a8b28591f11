#pragma once
// Result files replaced atomically: each is written in full to a temporary file beside it
// (flushed to disk), then renamed over it, so a failed run never leaves a half-written or
// damaged file where a good one was.
#include <filesystem>
#include <string>
#include <vector>

namespace shapectl {

struct FileContent {
  std::filesystem::path file;
  std::string text;
};

// Writes every file or none: all temporaries are written first, and only when every one was
// written are they renamed over their targets. Throws InputError naming the file if it cannot
// be written: its directory is missing, it is a directory, it is named twice, or a write fails
// (disk full, file size limit). Temporaries are removed on failure; their names (target name,
// ".tmp.", process id and a counter) never collide between concurrent runs.
// (Once the temporaries are written, a rename fails only if someone changes the directory at
// that moment; then the files renamed before it stay replaced.)
void write_files_atomically(const std::vector<FileContent>& files);
void write_file_atomically(const std::filesystem::path& file, const std::string& text);

// Whether `file` could be written now, checked before a long computation rather than after:
// its directory exists, it is not a directory, and a temporary can be created beside it (then
// removed; an existing file is not touched). Throws InputError naming the file, as above.
void check_writable(const std::filesystem::path& file);

}  // namespace shapectl
