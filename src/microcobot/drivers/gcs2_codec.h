#pragma once
/// @file
/// PI's General Command Set, GCS 2.0: the line syntax both the twin's server and
/// the real-controller driver speak. Documents followed (docs/hardware.md):
///  - PI, "GCS 2.0 commands" chapters of the E-873 (Q-Motion) and C-867 user manuals (PZ..E,
///    MS196E): LF-terminated ASCII lines, case-insensitive three-letter mnemonics, `?` queries,
///    replies `axis=value`, multi-line replies whose lines but the last end in space + LF, an
///    optional daisy-chain target address before the command (`2 POS?`) answered with the host
///    and sender addresses before the reply (`0 2 1=...`), single-byte commands without LF
///    (#5 motion status as a hex mask, #7 ready 0xB1 / busy 0xB0, #24 stop all), one error
///    register read and cleared by `ERR?`.
///  - PI's public Python library PIPython (gcscommands.py, gcsmessages.py, gcserror.py): the
///    reply parsing clients actually do (`int(answer, 16)` for #5, 0xB1/0xB0 for #7, the end of
///    a multi-line answer at a line not ending in space), and the error texts below.

#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mc::drivers::gcs2 {

/// Controller error codes (PI's table, PIPython gcserror.py).
enum Error : int {
  kNoError = 0,
  kParameterSyntax = 1,       ///< parameter syntax error
  kUnknownCommand = 2,        ///< unknown command
  kCommandTooLong = 3,        ///< command length out of limits or command buffer overrun
  kUnallowableMove = 5,       ///< move on an unreferenced axis, or with servo off
  kPositionOutOfLimits = 7,   ///< position out of limits
  kVelocityOutOfLimits = 8,   ///< velocity out of limits
  kStopped = 10,              ///< controller was stopped by command (HLT, STP, #24; the e-stop)
  kInvalidAxis = 15,          ///< invalid axis identifier
  kParameterOutOfRange = 17,  ///< parameter out of range
};
/// The controller's text of an error code ("Unknown command"); "Unknown error" otherwise.
std::string_view error_text(int code);

/// GCS 2.0 positions and velocities are in the axis' physical unit (PUN?): mm (mm/s) for linear
/// stages, deg (deg/s) for rotation stages.
inline constexpr double kMmPerM = 1e3;
inline constexpr double kDegPerRad = 180.0 / std::numbers::pi;

/// The single-byte commands (sent without LF).
inline constexpr char kMotionStatus = 5;  ///< #5: hex mask of the moving axes
inline constexpr char kReadyStatus = 7;   ///< #7: 0xB1 ready, 0xB0 busy
inline constexpr char kStopAll = 24;      ///< #24: stop every axis (error 10)
inline constexpr unsigned char kReady = 0xB1, kBusy = 0xB0;

/// The longest command line the twin accepts (PI's controllers refuse longer ones with error 3).
inline constexpr std::size_t kMaxLineLength = 256;

/// One command line, parsed.
struct Request {
  int target_address = 0;  ///< the daisy-chain address given before the command (0: none)
  std::string mnemonic;    ///< upper case, with its '?' ("POS?", "*IDN?", "MOV")
  std::vector<std::string> args;
  bool query() const { return !mnemonic.empty() && mnemonic.back() == '?'; }
};

/// Parses one line (its LF removed; a trailing CR is dropped). nullopt for a blank line. A
/// leading number is the target address (1..254), the next word the mnemonic (case-insensitive).
std::optional<Request> parse_line(std::string_view line);

/// The bytes of a reply: every line but the last ends in " \n", the last in "\n". With a
/// sender address (a request that gave a target address), each line starts with "0 <address> ".
std::string format_reply(const std::vector<std::string>& lines, int from_address = 0);

/// `axis=value` with the controller's fixed-point format (%.6f, mm or mm/s).
std::string axis_value(std::string_view axis, double value);
std::string axis_value(std::string_view axis, int value);

/// A strict number: the whole word, finite ("0.5", "-1e-3"); nullopt otherwise.
std::optional<double> parse_number(std::string_view word);

/// Splits a reply's text into its lines and parses `axis=value` pairs (driver side): the host
/// and sender prefix ("0 1 ") is removed when present. Throws mc::InvalidInput naming the line.
std::vector<std::pair<std::string, double>> parse_axis_values(std::string_view reply);

/// True once `text` (what arrived so far) holds a whole reply: ends in LF not preceded by a space.
bool reply_complete(std::string_view text);

/// Driver side: the length of the first whole reply at the start of `text` (through the LF of its
/// last line: the first LF not preceded by a space), 0 while it is incomplete.
std::size_t reply_end(std::string_view text);

/// Driver side: the code of an `ERR?` reply ("7", or "0 1 7" from a daisy-chained controller);
/// nullopt when the reply is not one integer in [-1e6, 1e6] (GCS codes are small, some negative).
std::optional<int> parse_error_reply(std::string_view reply);

/// Driver side: the lines of a reply, each without its trailing space, CR and LF and without the
/// host and sender addresses of a daisy-chained reply ("0 1 ").
std::vector<std::string> reply_lines(std::string_view reply);

}  // namespace mc::drivers::gcs2
