#pragma once
/// @file
/// The Foxglove WebSocket protocol v1 (subprotocol `foxglove.websocket.v1`) as pure functions:
/// the JSON messages the server sends (serverInfo, advertise, unadvertise, status), the client's
/// JSON operations parsed into typed structs (subscribe, unsubscribe, advertise, unadvertise),
/// and the binary frames (server messageData, client messageData). No sockets here, so every
/// rule is testable on its own; the transport is foxglove_server.h. docs/console.md, "Protocol".

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace mc::server {

/// The WebSocket subprotocol a client must offer on the upgrade.
inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";

/// A server channel id (advertised by the server), unique for the server's lifetime.
using ChannelId = std::uint32_t;
/// A subscription id, chosen by the client, unique among that client's active subscriptions.
using SubscriptionId = std::uint32_t;
/// A client channel id, chosen by the client in its `advertise`.
using ClientChannelId = std::uint32_t;
/// A connection id, unique for the server's lifetime (starts at 1).
using ClientId = std::uint32_t;

/// Severity of a `status` message (the protocol's numbers).
enum class StatusLevel : std::uint8_t { kInfo = 0, kWarning = 1, kError = 2 };

/// A channel the server publishes on (one `advertise` entry).
struct ChannelSpec {
  std::string topic;
  std::string encoding = "json";
  std::string schema_name;
  std::string schema_encoding = "jsonschema";
  std::string schema;
  /// A live view wants only the newest message (a camera's images): a new one replaces the
  /// message of this channel still queued for a client (never one being written), so a slow
  /// client gets fewer messages, not older ones. Not advertised: the server's own policy.
  bool latest_only = false;
};

/// A server channel with its id.
struct Channel {
  ChannelId id = 0;
  ChannelSpec spec;
};

/// The content of `serverInfo`.
struct ServerInfo {
  std::string name;
  std::vector<std::string> capabilities{"clientPublish"};
  std::vector<std::string> supported_encodings{"json"};
  std::map<std::string, std::string> metadata;
  std::string session_id;
};

/// One entry of a client's `subscribe`.
struct Subscription {
  SubscriptionId id = 0;
  ChannelId channel = 0;
};
/// `{"op":"subscribe","subscriptions":[{"id":..,"channelId":..}, ...]}`.
struct SubscribeOp {
  std::vector<Subscription> subscriptions;
};
/// `{"op":"unsubscribe","subscriptionIds":[...]}`.
struct UnsubscribeOp {
  std::vector<SubscriptionId> subscription_ids;
};
/// One channel of a client's `advertise` (the client publishes on it).
struct ClientChannel {
  ClientChannelId id = 0;
  std::string topic;
  std::string encoding;
  std::string schema_name;
};
/// `{"op":"advertise","channels":[{"id":..,"topic":..,"encoding":..,"schemaName":..}, ...]}`.
struct ClientAdvertiseOp {
  std::vector<ClientChannel> channels;
};
/// `{"op":"unadvertise","channelIds":[...]}`.
struct ClientUnadvertiseOp {
  std::vector<ClientChannelId> channel_ids;
};

/// A rejected input: `id` is a stable category (the status message's id, e.g. "malformed-json",
/// "unknown-op", "bad-field", "bad-binary") and `message` one line saying what was expected.
struct ProtocolError {
  std::string id;
  std::string message;
};

/// The result of parsing one client text message.
using ClientOp =
    std::variant<SubscribeOp, UnsubscribeOp, ClientAdvertiseOp, ClientUnadvertiseOp, ProtocolError>;

/// Parses one client text message. Never throws: malformed JSON, a non-object, a missing or
/// unknown `op`, or a field of the wrong type (ids must be integers in [0, 2^32)) give a
/// ProtocolError. Ops of the protocol the server does not support (parameters, services, ...)
/// are "unsupported-op".
ClientOp parse_client_text(std::string_view text);

/// Binary opcode of server messageData and of client messageData.
inline constexpr std::uint8_t kMessageDataOpcode = 0x01;
/// Bytes of the server messageData header: opcode, subscription id (u32 LE), log time (u64 LE).
inline constexpr std::size_t kMessageDataHeaderBytes = 13;
/// Bytes of the client messageData header: opcode, client channel id (u32 LE).
inline constexpr std::size_t kClientMessageHeaderBytes = 5;

/// A client binary messageData; `payload` views the frame it was parsed from.
struct ClientMessageData {
  ClientChannelId channel = 0;
  std::string_view payload;
};
/// Parses a client binary frame. Never throws: an empty or short frame or an unknown opcode
/// gives ProtocolError{"bad-binary", ...}.
std::variant<ClientMessageData, ProtocolError> parse_client_binary(std::string_view frame);

/// The 13-byte header of a server messageData frame (the payload follows it).
std::array<char, kMessageDataHeaderBytes> message_data_header(SubscriptionId subscription,
                                                              std::uint64_t log_time_ns);
/// A whole server messageData frame (header + payload).
std::string encode_message_data(SubscriptionId subscription, std::uint64_t log_time_ns,
                                std::string_view payload);

/// A server messageData frame decoded (for clients and tests); `payload` views the frame.
struct MessageData {
  SubscriptionId subscription = 0;
  std::uint64_t log_time_ns = 0;
  std::string_view payload;
};
/// Decodes a server messageData frame; ProtocolError when short or of another opcode.
std::variant<MessageData, ProtocolError> decode_message_data(std::string_view frame);
/// A whole client messageData frame (header + payload), for clients and tests.
std::string encode_client_message_data(ClientChannelId channel, std::string_view payload);

/// `serverInfo` as JSON text.
std::string server_info_json(const ServerInfo& info);
/// `advertise` of the given channels as JSON text.
std::string advertise_json(const std::vector<Channel>& channels);
/// `unadvertise` of the given channel ids as JSON text.
std::string unadvertise_json(const std::vector<ChannelId>& ids);
/// `status` as JSON text; `message` is made one line (control characters become spaces) and
/// bounded to 512 bytes; invalid UTF-8 is replaced.
std::string status_json(StatusLevel level, std::string_view message, std::string_view id);

/// `text` with control characters replaced by spaces and cut to `max_bytes` ("..." appended).
std::string one_line(std::string_view text, std::size_t max_bytes = 200);

}  // namespace mc::server
