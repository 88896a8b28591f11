#include <shapectl/io/input_file.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <shapectl/io/input_error.hpp>

namespace shapectl {

namespace {

std::string file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

// Closes the descriptor on every path out.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) close(fd);
  }
};

}  // namespace

std::filesystem::path resolved_path(const std::filesystem::path& path) {
  std::error_code error;
  const std::filesystem::path cwd = std::filesystem::current_path(error);
  const std::filesystem::path normal = (cwd / path).lexically_normal();
  // "/a/b/" (from "." or "") shown as "/a/b".
  return normal.has_filename() || normal == normal.root_path() ? normal : normal.parent_path();
}

std::string read_input_file(const std::filesystem::path& file, std::uintmax_t max_bytes,
                            std::string_view what) {
  const std::string name = file.string();
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the type is checked on the open
  // descriptor, so the file cannot be swapped between the check and the read.
  const Descriptor in{open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (in.fd < 0) {
    const int error = errno;
    const std::string resolved = error == ENOENT && file.is_relative()
                                     ? "; relative to the current directory " +
                                           resolved_path("").string() + ": " +
                                           resolved_path(file).string()
                                     : "";
    throw InputError(name, "",
                     "cannot open file (" + std::string(std::strerror(error)) + resolved + ")");
  }
  struct stat info {};
  if (fstat(in.fd, &info) != 0)
    throw InputError(name, "", "cannot open file (" + std::string(std::strerror(errno)) + ")");
  if (!S_ISREG(info.st_mode))
    throw InputError(name, "", "not a regular file (" + file_kind(info.st_mode) + ")");
  const std::string limit = "larger than the " + std::to_string(max_bytes) + " byte limit for " +
                            std::string(what) + " files";
  if (static_cast<std::uintmax_t>(info.st_size) > max_bytes)
    throw InputError(name, "", limit + " (" + std::to_string(info.st_size) + " bytes)");
  std::string text;
  text.reserve(static_cast<std::size_t>(info.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = read(in.fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0)
      throw InputError(name, "", "cannot read file (" + std::string(std::strerror(errno)) + ")");
    if (n == 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
    if (text.size() > max_bytes) throw InputError(name, "", limit);  // it grew while we read
  }
  return text;
}

std::string bounded_preview(std::string_view text, std::size_t max_chars) {
  std::size_t end = std::min(text.size(), max_chars);
  // Do not split a multi-byte UTF-8 character: back up over continuation bytes.
  if (end < text.size())
    while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  std::string out(text.substr(0, end));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  return end < text.size() ? out + "…" : out;
}

}  // namespace shapectl
