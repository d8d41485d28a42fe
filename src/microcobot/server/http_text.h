#pragma once
/// @file
/// The text rules of the HTTP side of the server, as pure functions on strings: comparing the
/// access token, reading a query parameter of a request target and checking the WebSocket
/// subprotocol offer. No Beast here (the transport is foxglove_server.cc, ws_session.cc and
/// http_session.cc), so each rule is testable on its own and cheap to compile.

#include <optional>
#include <string>
#include <string_view>

namespace mc::server {

/// Equality whose time depends only on the length of `expected` (the secret), not on where the
/// strings differ. The access token is compared with it so that the answer time of a wrong token
/// does not tell an attacker how many of its leading characters are right.
bool constant_time_equal(std::string_view expected, std::string_view given);

/// Decodes a query component: `%XY` (two hex digits) becomes that byte and `+` a space; a `%`
/// without two hex digits after it is kept as it is. A browser encodes a token this way in a URL.
std::string percent_decode(std::string_view s);

/// The value of query parameter `key` in a request target (`/path?a=1&key=value`),
/// percent-decoded; the first one when repeated, an empty string for `key` without `=`, nullopt
/// when absent.
std::optional<std::string> query_param(std::string_view target, std::string_view key);

/// Whether a Sec-WebSocket-Protocol header (a comma-separated list, items trimmed of spaces and
/// tabs) lists the Foxglove subprotocol (kSubprotocol): the server upgrades only a client that
/// speaks it.
bool offers_subprotocol(std::string_view header);

}  // namespace mc::server
