#pragma once
/// @file
/// SmarAct's MCS2 ASCII command interface (SCPI-like, TCP port 55551): the line syntax both the
/// twin's server and a real-controller driver speak. Sources followed (docs/hardware.md):
///  - the EPICS motorSmarAct MCS2 driver (smarActMCS2MotorDriver.{h,cpp}, README.SmarActMCS2): CR LF
///    line ends, 0-based channels (`:CHAN0:STAT?`), set commands unanswered and queries answered
///    with one line, `:MOVE<n>` with a decimal (`%f`) or integer step count, positions in pm
///    (linear) and ndeg (rotary) as 64-bit integers, `:CHAN<n>:HOLD -1` (hold forever), the channel
///    state bits, the reference option bits, `:SYST:ERR:COUN?` then `:SYST:ERR?` to drain the
///    error queue, and the error codes it decodes (SCPI's negative ones, 34, 259).
///  - kamzik3's MCS2 device (deviceSmaractMcs2.py): every command followed by `:SYST:ERR:NEXT?`,
///    whose reply `<code>,"<text>"` it matches with `([-0-9]+),"([\w ]+)"` (so the texts here are
///    words and spaces only); `:TUN:BASE:UNIT?` 2 = metre, `:TUN:BASE:RES?` -12 = pm; `SENS:MODE`
///    0 disabled, 1 enabled, 2 power save; `MMOD` 0 absolute, 1 relative, 2-3 scan, 4 step;
///    `STEP:AMPL` 1..65535, `STEP:FREQ` 1..20000 Hz.
///  - SmarAct's SmarActControl constants (SmarActControlConstants.h as published with the SDK's
///    examples): the numeric error codes (0x0022 invalid channel index, 0x0103 no sensor present,
///    0x0112 not referenced, ...), the channel, module and device state bits, the base units.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mc::drivers::mcs2 {

inline constexpr std::string_view kEol = "\r\n";
/// The controller's TCP port.
inline constexpr std::uint16_t kDefaultPort = 55551;
/// The longest line the twin accepts; a longer one is answered by error -363 (input buffer overrun).
inline constexpr std::size_t kMaxLineLength = 512;
/// The error queue's depth: one more error replaces the last entry by -350 (SCPI's queue overflow).
inline constexpr std::size_t kErrorQueueDepth = 20;

/// Error codes: SCPI's command errors (negative) and SmarActControl's device errors (positive).
enum Error : int {
  kNoError = 0,
  kInvalidCharacter = -101,
  kInvalidSeparator = -103,
  kDataTypeError = -104,
  kParameterNotAllowed = -108,
  kMissingParameter = -109,
  kUndefinedHeader = -113,
  kHeaderSuffixOutOfRange = -114,
  kDataOutOfRange = -222,
  kQueueOverflow = -350,
  kInputBufferOverrun = -363,
  kAborted = 0x0019,
  kInvalidModuleIndex = 0x0021,
  kInvalidChannelIndex = 0x0022,
  kPermissionDenied = 0x0023,
  kMovementLocked = 0x0025,
  kNoSensorPresent = 0x0103,
  kSensorDisabled = 0x0104,
  kAmplifierDisabled = 0x0106,
  kNotReferenced = 0x0112,
  kBusyReferencing = 0x0152,
  kRangeLimitReached = 0x0202,
  kFeatureNotImplemented = 0x7ffe,
};
/// The text of an error code (words and spaces only); "Unknown error" otherwise.
std::string_view error_text(int code);
/// `<code>,"<text>"`, the reply of `:SYST:ERR?`.
std::string format_error(int code);

/// Channel state bits (`:CHAN<n>:STAT?`).
namespace channel_state {
inline constexpr std::uint32_t kActivelyMoving = 0x0001;
inline constexpr std::uint32_t kClosedLoopActive = 0x0002;
inline constexpr std::uint32_t kCalibrating = 0x0004;
inline constexpr std::uint32_t kReferencing = 0x0008;
inline constexpr std::uint32_t kMoveDelayed = 0x0010;
inline constexpr std::uint32_t kSensorPresent = 0x0020;
inline constexpr std::uint32_t kIsCalibrated = 0x0040;
inline constexpr std::uint32_t kIsReferenced = 0x0080;
inline constexpr std::uint32_t kEndStopReached = 0x0100;
inline constexpr std::uint32_t kRangeLimitReached = 0x0200;
inline constexpr std::uint32_t kFollowingLimitReached = 0x0400;
inline constexpr std::uint32_t kMovementFailed = 0x0800;
inline constexpr std::uint32_t kIsStreaming = 0x1000;
inline constexpr std::uint32_t kPositionerOverload = 0x2000;
inline constexpr std::uint32_t kOverTemperature = 0x4000;
inline constexpr std::uint32_t kReferenceMark = 0x8000;
inline constexpr std::uint32_t kAmplifierEnabled = 0x40000;
inline constexpr std::uint32_t kInPosition = 0x80000;
}  // namespace channel_state

/// Device state bits (`:DEV:STAT?`) and module state bits (`:MOD<m>:STAT?`).
inline constexpr std::uint32_t kDeviceMovementLocked = 0x0002;
inline constexpr std::uint32_t kModuleSensorModulePresent = 0x0001;

/// `MMOD`'s move modes.
enum MoveMode : int { kAbsolute = 0, kRelative = 1, kScanAbsolute = 2, kScanRelative = 3, kStep = 4 };
/// `SENS:MODE`'s sensor modes.
enum SensorMode : int { kSensorOff = 0, kSensorOn = 1, kSensorPowerSave = 2 };
/// `TUN:BASE:UNIT?`: metre (pm positions) or degree (ndeg positions).
inline constexpr int kUnitMeter = 2, kUnitDegree = 3;
/// `TUN:BASE:RES?`: the exponent of the position unit (pm, ndeg).
inline constexpr int kResolutionLinear = -12, kResolutionRotary = -9;
/// `STEP:AMPL`'s full scale: 65535 is 100 V.
inline constexpr int kFullAmplitude = 65535;
inline constexpr double kFullAmplitude_V = 100.0;
inline constexpr int kMaxStepFrequency_Hz = 20000;
/// The largest step count of one `:MOVE<n>` in step mode.
inline constexpr std::int64_t kMaxSteps = 100000;
/// `REF:OPT` bits: start direction, reverse direction, auto zero, abort on end stop, continue on
/// reference found, stop on reference found.
inline constexpr int kRefOptAutoZero = 0x0004, kRefOptMask = 0x003f;

/// One command of a line, parsed.
struct Command {
  /// The header's nodes in their short form, upper case, joined by ':', without the numeric
  /// suffix and the '?': "CHAN:POS:CURR", "MOVE", "SYST:ERR:NEXT", "*IDN".
  std::string header;
  int index = -1;                 ///< the numeric suffix (`:CHAN2` → 2, `:MOVE0` → 0), -1 without one
  bool query = false;             ///< the header ended in '?'
  std::vector<std::string> args;  ///< the comma-separated parameters, trimmed
};

/// The commands of one line (its CR LF removed): split at ';', blank ones dropped.
std::vector<std::string_view> split_commands(std::string_view line);

/// Parses one command into `out`; kNoError, or the SCPI error its syntax earns (-101 a control
/// character, -113 an empty or unknown-shaped header, -114 a suffix over 3 digits, -103 a
/// parameter list that ends or starts with ',').
int parse_command(std::string_view text, Command& out);

/// A strict integer: the whole word, an optional sign and decimal digits, within int64.
std::optional<std::int64_t> parse_integer(std::string_view word);
/// An integer or a decimal ("1000000.000000", "-2.5e3"), rounded to the nearest integer; nullopt
/// when not a finite number within +-9e18.
std::optional<std::int64_t> parse_rounded(std::string_view word);

/// Driver side: the code and text of a `<code>,"<text>"` reply (CR LF tolerated); nullopt when
/// the reply is not one.
std::optional<std::pair<int, std::string>> parse_error_reply(std::string_view reply);

/// Driver side: the length of the first whole reply line at the start of `text` (through its CR
/// LF; a bare LF is tolerated), 0 while it is incomplete.
std::size_t reply_end(std::string_view text);

}  // namespace mc::drivers::mcs2
