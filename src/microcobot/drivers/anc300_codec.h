#pragma once
/// @file
/// The Attocube ANC300's console protocol, shared by the twin's server and the
/// real-controller driver. Documents followed (docs/hardware.md):
///  - attocube systems, "ANC300 Piezo Motion Controller, user manual", chapter "Command
///    reference" of the ASCII console (telnet TCP 7230 or serial): `setm/getm`, `setf/getf`,
///    `setv/getv`, `stepu/stepd AXIS N`, `stepw`, `stop`, `getc`; replies `name = value unit`,
///    each reply ending with an `OK` or `ERROR` line; the console asks for a password first
///    (factory password 123456); `echo off` stops the echo of the typed line and the prompt.
///  - pymeasure's ANC300 driver (Debian python3-pymeasure,
///    pymeasure/instruments/attocube/{adapters,anc300}.py): CR LF line ends, the authorisation
///    reply read as the second line `Authorization success`, set commands acknowledged by a
///    first line `OK`, values read with the pattern `\w+\s+=\s+(\w+)`.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mc::drivers::anc300 {

inline constexpr std::string_view kEol = "\r\n";
inline constexpr std::string_view kOk = "OK";
inline constexpr std::string_view kError = "ERROR";
inline constexpr std::string_view kFactoryPassword = "123456";
inline constexpr std::string_view kPasswordPrompt = "Authorization code: ";
inline constexpr std::string_view kAuthorized = "Authorization success";
inline constexpr std::string_view kNotAuthorized = "Authorization failed";
inline constexpr std::string_view kPrompt = "> ";
inline constexpr std::size_t kMaxLineLength = 256;

/// Axis modes (the ANC300's `setm` names).
enum class Mode { kGnd, kInp, kCap, kStp, kOff, kStpPlus, kStpMinus };
std::string_view mode_name(Mode m);
std::optional<Mode> parse_mode(std::string_view name);

struct Request {
  std::string command;  ///< lower case ("setf")
  std::vector<std::string> args;
};
/// Parses one line (CR, LF removed); nullopt for a blank line.
std::optional<Request> parse_line(std::string_view line);

/// "name = value unit" as the controller prints it ("frequency = 500 Hz").
std::string value_line(std::string_view name, std::string_view value, std::string_view unit = "");
/// A whole reply: the lines, then OK (or the error's message, then ERROR), each with CR LF.
std::string reply_ok(const std::vector<std::string>& lines = {});
std::string reply_error(std::string_view message);

/// A strict number (the whole word, finite); nullopt otherwise.
std::optional<double> parse_number(std::string_view word);
/// A strict non-negative integer; nullopt otherwise.
std::optional<long long> parse_count(std::string_view word);

/// Driver side: the value of a "name = value [unit]" line (nullopt when the line is not one).
std::optional<std::string> value_of(std::string_view line);

/// Driver side (echo off): the length of the first whole reply at the start of `text`, through its
/// `OK` or `ERROR` line and that line's CR LF (a prompt "> " before it is tolerated), 0 while it
/// is incomplete; `*ok` says which line ended it.
std::size_t reply_end(std::string_view text, bool* ok = nullptr);

/// Driver side: the lines of a whole reply before its OK/ERROR line, CR LF removed, blank lines
/// and prompts dropped (an ERROR reply's message is its last line).
std::vector<std::string> reply_lines(std::string_view reply);

}  // namespace mc::drivers::anc300
