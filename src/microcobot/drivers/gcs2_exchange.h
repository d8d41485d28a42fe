#pragma once
/// @file
/// One GCS 2.0 exchange on a driver's bus, shared by the PI drivers (gcs2_driver.h,
/// pi_hexapod_controller.h): a query and its reply, a set command checked with ERR?, the error
/// state read until clear. Every failure is a BusFault naming the line and what came back.
/// Runs on the bus thread only (it blocks up to its deadline).

#include <chrono>
#include <string>
#include <string_view>

#include "microcobot/drivers/line_client.h"

namespace mc::drivers::gcs2 {

using Clock = std::chrono::steady_clock;

/// The name a line goes by in errors: `#5` for a single-byte command (GCS's #5, #24: sent
/// without a line end), the line cut to 60 characters otherwise.
std::string line_name(const std::string& line);

/// Sends `line` (LF-terminated; a single-byte command as it is) and reads its reply up to its
/// last line (gcs2::reply_end), all before `deadline`. Throws BusFault naming the line, the
/// bus' error and the part of a reply that came.
std::string query(LineClient& bus, const std::string& line, Clock::time_point deadline);

/// The text of an error code in a controller's table (gcs2::error_text, gcs2::hexapod_error_text).
using ErrorText = std::string_view (*)(int);

/// Sends the set command `line`, then `ERR?`, each before its own deadline `reply_timeout`
/// from its start: GCS set commands have no reply, so ERR? is how a refusal shows. Throws
/// BusFault naming the line, the code and `text(code)` unless the code is 0 or `also_ok`.
void command(LineClient& bus, const std::string& line, Clock::duration reply_timeout, ErrorText text,
             int also_ok = 0);

/// Reads `ERR?` until it reads 0 (a controller keeps the last error of an earlier session), at
/// most `max_reads` times. Throws BusFault on a reply that is not a code or an error that stays.
void clear_errors(LineClient& bus, Clock::duration reply_timeout, int max_reads = 16);

}  // namespace mc::drivers::gcs2
