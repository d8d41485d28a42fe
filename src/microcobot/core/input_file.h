#pragma once
/// @file
/// Reading input files safely: every file the platform reads (parameter and configuration
/// YAML, CSV data) goes through read_input_file(), which accepts only regular files (a
/// directory, a device such as /dev/zero or a FIFO is refused before it is read) and refuses
/// files larger than a cap before reading them (.mat files: core/mat_file does the same checks), so a bad
/// path can neither hang the command nor exhaust memory. Also the helpers that keep error messages to one
/// readable line.

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace mc {

/// The largest parameter or configuration file (YAML) accepted: 1 MiB.
inline constexpr std::size_t kMaxParamsFileBytes = std::size_t{1} << 20;
/// The largest CSV data file accepted: 512 MiB.
inline constexpr std::size_t kMaxCsvFileBytes = std::size_t{512} << 20;

/// The whole content of `file`. Throws InvalidInput "<file>: <what>" when it does not exist,
/// cannot be opened, is not a regular file (directory, device, FIFO, socket) or holds more
/// than `max_bytes` bytes (`kind` names the cap in the message, e.g. "parameter file").
std::string read_input_file(const std::filesystem::path& file, std::size_t max_bytes, std::string_view kind);

/// `text` for a one-line message: control characters and bytes outside printable ASCII
/// escaped as \n, \r, \t or \xHH, and the printed form cut to `max_chars` characters (then
/// "...").
std::string excerpt(std::string_view text, std::size_t max_chars = 80);

/// A number in messages: `%g` style (shortest of fixed/scientific, 6 significant digits), so
/// DBL_MAX reads 1.79769e+308 and 1e-10 reads 1e-10.
std::string fmt_number(double value);

}  // namespace mc
