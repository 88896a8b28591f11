#pragma once
// Reading an input file with its size bounded before any byte is read: a FIFO, a device or a
// huge file is refused with a message instead of hanging or exhausting memory.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace shapectl {

// Size limits per kind of input file, in bytes.
inline constexpr std::uintmax_t max_json_file_bytes = 8u << 20;   // scene, targets, joints, spheres
inline constexpr std::uintmax_t max_urdf_file_bytes = 16u << 20;  // YuMi's is 22 kB
inline constexpr std::uintmax_t max_mesh_file_bytes = 256u << 20;  // a million-tet MSH is ~60 MB
inline constexpr std::uintmax_t max_session_log_bytes = 1u
                                                        << 30;  // an hour of EGM at 250 Hz: ~400 MB

// The whole file. Throws InputError naming the file: "cannot open file (<reason>)" when it is
// missing (a relative name also says what it was resolved to, relative to the current
// directory) or unreadable, "not a regular file (...)" for a directory, FIFO or device, and
// "larger than the <max_bytes> byte limit for <what> files" when it is too big.
// `what` names the kind of file in that message ("JSON", "URDF", "mesh").
std::string read_input_file(const std::filesystem::path& file, std::uintmax_t max_bytes,
                            std::string_view what);

// `path` made absolute against the current directory and normalized ("a/../b" → "/cwd/b"), as a
// message shows where a relative path led; "" is the current directory.
std::filesystem::path resolved_path(const std::filesystem::path& path);

// `text` as it may appear in a message: at most `max_chars` bytes (cut at a UTF-8 character
// boundary, then "…"), control characters as '?', so no input can flood or garble a message.
std::string bounded_preview(std::string_view text, std::size_t max_chars = 80);

}  // namespace shapectl
