#include <shapectl/io/atomic_file.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const fs::path& file, const std::string& problem) {
  throw InputError(file.string(), "", "cannot write: " + problem);
}

// A target we could replace: its directory exists and it is not itself a directory.
void check_target(const fs::path& file) {
  const fs::path directory = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  std::error_code ec;
  if (!fs::is_directory(directory, ec))
    fail(file, "directory '" + directory.string() + "' does not exist");
  if (fs::is_directory(file, ec)) fail(file, "it is a directory");
  if (file.filename().empty()) fail(file, "no file name");
}

// Creates a temporary file beside `file` that no other run uses (O_EXCL), writes `text` and
// flushes it to disk. Returns its path; on failure removes it and throws.
fs::path write_temporary(const fs::path& file, const std::string& text) {
  static std::atomic<unsigned> counter{0};
  fs::path temporary;
  int fd = -1;
  for (int attempt = 0; fd < 0; ++attempt) {
    temporary =
        file.string() + ".tmp." + std::to_string(getpid()) + "." + std::to_string(counter++);
    fd = open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && (errno != EEXIST || attempt >= 100))
      fail(file, "cannot create '" + temporary.string() + "': " + std::strerror(errno));
  }
  std::size_t written = 0;
  int error = 0;
  while (written < text.size()) {
    const ssize_t n = write(fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = n < 0 ? errno : EIO;
      break;
    }
    written += static_cast<std::size_t>(n);
  }
  if (!error && fsync(fd) != 0 && errno != EINVAL) error = errno;  // EINVAL: no fsync here
  if (close(fd) != 0 && !error) error = errno;
  if (error) {
    std::error_code ec;
    fs::remove(temporary, ec);
    fail(file, std::string("writing '") + temporary.string() + "' failed: " + std::strerror(error));
  }
  return temporary;
}

bool same_path(const fs::path& a, const fs::path& b) {
  std::error_code ec_a, ec_b;
  const fs::path ca = fs::weakly_canonical(a, ec_a), cb = fs::weakly_canonical(b, ec_b);
  return ec_a || ec_b ? a.lexically_normal() == b.lexically_normal() : ca == cb;
}

}  // namespace

void write_files_atomically(const std::vector<FileContent>& files) {
  for (std::size_t k = 0; k < files.size(); ++k) {
    check_target(files[k].file);
    for (std::size_t j = 0; j < k; ++j)
      if (same_path(files[j].file, files[k].file)) fail(files[k].file, "named twice");
  }
  std::vector<fs::path> temporaries;
  auto remove_temporaries = [&](std::size_t from) {
    std::error_code ec;
    for (std::size_t k = from; k < temporaries.size(); ++k) fs::remove(temporaries[k], ec);
  };
  try {
    for (const auto& f : files) temporaries.push_back(write_temporary(f.file, f.text));
  } catch (...) {
    remove_temporaries(0);
    throw;
  }
  for (std::size_t k = 0; k < files.size(); ++k) {
    std::error_code ec;
    fs::rename(temporaries[k], files[k].file, ec);
    if (ec) {
      remove_temporaries(k);
      fail(files[k].file, ec.message());
    }
  }
}

void write_file_atomically(const fs::path& file, const std::string& text) {
  write_files_atomically({{file, text}});
}

void check_writable(const fs::path& file) {
  check_target(file);
  std::error_code ec;
  fs::remove(write_temporary(file, ""), ec);  // permissions, a read-only file system, quotas
}

}  // namespace shapectl
