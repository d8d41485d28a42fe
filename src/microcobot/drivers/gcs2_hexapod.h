#pragma once
/// @file
/// The PI hexapod (C-887) dialect of GCS 2.0: what its lines carry beyond gcs2_codec.h's syntax.
/// Documents followed (docs/hardware.md, "PI hexapod (C-887) dialect"):
///  - PI's hexapod manuals (C-887 controller, H-811/H-820 hexapods): six axes X, Y, Z (mm) and
///    U, V, W (deg, rotations U -> V -> W about axes moving with the platform), the pivot point's
///    coordinates R, S, T (mm) set by SPI only while U, V and W are all 0, the system velocity VLS,
///    user coordinate systems defined with KSD and enabled with KEN (ZERO is the root one).
///  - PIPython's gcscommands.py (KSD, KEN, qKEN, VLS, qVLS, SPI, qSPI, qVMO: the argument order
///    and the reply parsing: qVMO compares the reply with "1\n") and gcserror.py (the codes below).
/// Pure functions: the twin (twins/gcs2_hexapod_twin.h) and a client share them.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mc::drivers::gcs2 {

/// The C-887's codes beyond gcs2::Error (PI's table, PIPython gcserror.py).
enum HexapodError : int {
  kSetPivotNotPossible = 9,  ///< attempt to set pivot point while U, V and W not all 0
  kAxisTwice = 22,           ///< axis identifier specified more than once
  kCsDoesNotExist = 530,     ///< a command refers to a coordinate system that does not exist
  kCsInUse = 532,            ///< attempt to delete or change a coordinate system that is in use
  kCsWhileMoving = 536,      ///< coordinate system cannot be defined as long as Hexapod is in motion
  kCsNameInvalid = 557,      ///< name of coordinate system is invalid
  kControllerBusy = 1005,    ///< controller is busy with some lengthy operation (e.g. reference move)
};

/// The hexapod's axes in order, and the pivot point's.
inline constexpr std::array<const char*, 6> kHexapodAxes = {"X", "Y", "Z", "U", "V", "W"};
inline constexpr std::array<const char*, 3> kPivotAxes = {"R", "S", "T"};
/// The root coordinate system (KEN ZERO disables every user one).
inline constexpr std::string_view kZeroCs = "ZERO";
/// The longest coordinate system name the twin accepts (the C-887's names are short words).
inline constexpr std::size_t kMaxCsName = 8;

/// One value per named axis; nullopt where the line names none.
template <std::size_t N>
using AxisValues = std::array<std::optional<double>, N>;

/// `{<axis> <value>}` pairs over the axes `names` (case-insensitive): the values by axis, or the
/// GCS error of the first fault: kParameterSyntax (odd count, none, a bad number),
/// kInvalidAxis (an axis not in `names`), kAxisTwice (one named twice).
struct ParsedValues6 {
  AxisValues<6> values;
  int error = 0;
};
struct ParsedValues3 {
  AxisValues<3> values;
  int error = 0;
};
ParsedValues6 parse_hexapod_values(const std::vector<std::string>& args);
ParsedValues3 parse_pivot_values(const std::vector<std::string>& args);

/// The axes a query names (`POS? X U`, in the order given), all of them without arguments or with
/// ALL; `error` is kInvalidAxis for a name that is none of them, 0 otherwise.
struct QueriedAxes {
  std::vector<int> axes;  ///< indices into kHexapodAxes (or kPivotAxes)
  int error = 0;
};
QueriedAxes parse_hexapod_query(const std::vector<std::string>& args);
QueriedAxes parse_pivot_query(const std::vector<std::string>& args);

/// A coordinate system name: 1..kMaxCsName letters, digits or '_', starting with a letter, upper
/// case (GCS is case-insensitive: the name is returned upper case); nullopt otherwise (kCsNameInvalid).
std::optional<std::string> parse_cs_name(std::string_view word);

/// The text of the dialect's codes (gcs2::error_text's otherwise).
std::string_view hexapod_error_text(int code);

}  // namespace mc::drivers::gcs2
