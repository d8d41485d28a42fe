#include "microcobot/server/foxglove_protocol.h"

#include <algorithm>
#include <limits>
#include <nlohmann/json.hpp>

namespace mc::server {
namespace {

using nlohmann::json;

/// Nesting deeper than this is refused before parsing (no client message needs more than 4).
constexpr int kMaxJsonDepth = 16;

std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

ProtocolError error(std::string id, std::string message) { return {std::move(id), std::move(message)}; }

/// The deepest nesting of arrays/objects in `text`, scanning outside strings; stops counting
/// once above the limit. Malformed text is left to the parser.
int json_depth(std::string_view text) {
  int depth = 0;
  int max_depth = 0;
  bool in_string = false;
  bool escaped = false;
  for (char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      max_depth = std::max(max_depth, ++depth);
      if (max_depth > kMaxJsonDepth) return max_depth;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return max_depth;
}

/// Reads obj[key] as an id (integer in [0, 2^32)); false with `err` set otherwise.
bool get_u32(const json& obj, const char* key, std::uint32_t& out, std::string& err,
             const std::string& where) {
  const auto it = obj.find(key);
  if (it == obj.end()) {
    err = where + "." + key + " is missing";
    return false;
  }
  if (!it->is_number_unsigned() || it->get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max()) {
    err = where + "." + key + " must be an integer in [0, 4294967295]";
    return false;
  }
  out = static_cast<std::uint32_t>(it->get<std::uint64_t>());
  return true;
}

/// Reads obj[key] as a string; when absent, `required` decides between an error and "".
bool get_string(const json& obj, const char* key, bool required, std::string& out, std::string& err,
                const std::string& where) {
  const auto it = obj.find(key);
  if (it == obj.end()) {
    if (!required) return true;
    err = where + "." + key + " is missing";
    return false;
  }
  if (!it->is_string()) {
    err = where + "." + key + " must be a string";
    return false;
  }
  out = it->get<std::string>();
  return true;
}

/// obj[key] as an array, or nullptr with `err` set.
const json* get_array(const json& obj, const char* key, std::string& err, const std::string& op) {
  const auto it = obj.find(key);
  if (it == obj.end() || !it->is_array()) {
    err = op + ": " + key + " must be an array";
    return nullptr;
  }
  return &*it;
}

ClientOp parse_subscribe(const json& j) {
  std::string err;
  const json* subs = get_array(j, "subscriptions", err, "subscribe");
  if (subs == nullptr) return error("bad-field", err);
  SubscribeOp op;
  op.subscriptions.reserve(subs->size());
  for (std::size_t i = 0; i < subs->size(); ++i) {
    const json& s = (*subs)[i];
    const std::string where = "subscribe: subscriptions[" + std::to_string(i) + "]";
    if (!s.is_object()) return error("bad-field", where + " must be an object");
    Subscription sub;
    if (!get_u32(s, "id", sub.id, err, where) || !get_u32(s, "channelId", sub.channel, err, where)) {
      return error("bad-field", err);
    }
    op.subscriptions.push_back(sub);
  }
  return op;
}

/// Parses an array of ids (unsubscribe's subscriptionIds, unadvertise's channelIds).
bool parse_ids(const json& j, const char* key, const std::string& op, std::vector<std::uint32_t>& ids,
               std::string& err) {
  const json* arr = get_array(j, key, err, op);
  if (arr == nullptr) return false;
  ids.reserve(arr->size());
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const json& v = (*arr)[i];
    if (!v.is_number_unsigned() || v.get<std::uint64_t>() > std::numeric_limits<std::uint32_t>::max()) {
      err = op + ": " + key + "[" + std::to_string(i) + "] must be an integer in [0, 4294967295]";
      return false;
    }
    ids.push_back(static_cast<std::uint32_t>(v.get<std::uint64_t>()));
  }
  return true;
}

ClientOp parse_advertise(const json& j) {
  std::string err;
  const json* chans = get_array(j, "channels", err, "advertise");
  if (chans == nullptr) return error("bad-field", err);
  ClientAdvertiseOp op;
  op.channels.reserve(chans->size());
  for (std::size_t i = 0; i < chans->size(); ++i) {
    const json& c = (*chans)[i];
    const std::string where = "advertise: channels[" + std::to_string(i) + "]";
    if (!c.is_object()) return error("bad-field", where + " must be an object");
    ClientChannel ch;
    if (!get_u32(c, "id", ch.id, err, where) || !get_string(c, "topic", true, ch.topic, err, where) ||
        !get_string(c, "encoding", true, ch.encoding, err, where) ||
        !get_string(c, "schemaName", false, ch.schema_name, err, where)) {
      return error("bad-field", err);
    }
    op.channels.push_back(std::move(ch));
  }
  return op;
}

void put_u32(char* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<char>((v >> (8 * i)) & 0xffu);
}
void put_u64(char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<char>((v >> (8 * i)) & 0xffu);
}
std::uint32_t get_u32_le(const char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}
std::uint64_t get_u64_le(const char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(p[i]);
  return v;
}

}  // namespace

std::string one_line(std::string_view text, std::size_t max_bytes) {
  std::string out(text.substr(0, max_bytes));
  for (char& c : out) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) c = ' ';
  }
  if (text.size() > max_bytes) out += "...";
  return out;
}

ClientOp parse_client_text(std::string_view text) {
  if (json_depth(text) > kMaxJsonDepth) {
    return error("malformed-json", "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  }
  json j;
  try {
    j = json::parse(text.begin(), text.end());
  } catch (const json::parse_error& e) {
    return error("malformed-json", "malformed JSON at byte " + std::to_string(e.byte) +
                                       " (expected a JSON object with an \"op\" field)");
  } catch (const std::exception&) {
    return error("malformed-json", "malformed JSON (expected a JSON object with an \"op\" field)");
  }
  if (!j.is_object()) return error("malformed-json", "expected a JSON object with an \"op\" field");
  const auto op_it = j.find("op");
  if (op_it == j.end() || !op_it->is_string()) return error("bad-field", "\"op\" must be a string");
  const auto& op = op_it->get_ref<const std::string&>();
  try {
    if (op == "subscribe") return parse_subscribe(j);
    if (op == "unsubscribe") {
      UnsubscribeOp u;
      std::string err;
      if (!parse_ids(j, "subscriptionIds", op, u.subscription_ids, err)) return error("bad-field", err);
      return u;
    }
    if (op == "advertise") return parse_advertise(j);
    if (op == "unadvertise") {
      ClientUnadvertiseOp u;
      std::string err;
      if (!parse_ids(j, "channelIds", op, u.channel_ids, err)) return error("bad-field", err);
      return u;
    }
  } catch (const std::exception&) {
    // get<>() on a checked type does not throw; this only guards allocation failures.
    return error("bad-field", "cannot read op " + one_line(op, 64));
  }
  static constexpr std::string_view kUnsupported[] = {"getParameters",
                                                      "setParameters",
                                                      "subscribeParameterUpdates",
                                                      "unsubscribeParameterUpdates",
                                                      "subscribeConnectionGraph",
                                                      "unsubscribeConnectionGraph",
                                                      "fetchAsset"};
  if (std::find(std::begin(kUnsupported), std::end(kUnsupported), op) != std::end(kUnsupported)) {
    return error("unsupported-op", "op \"" + op + "\" is not supported by this server");
  }
  return error("unknown-op", "unknown op \"" + one_line(op, 64) +
                                 "\" (expected subscribe, unsubscribe, advertise or unadvertise)");
}

std::variant<ClientMessageData, ProtocolError> parse_client_binary(std::string_view frame) {
  if (frame.empty()) return error("bad-binary", "empty binary message");
  const auto opcode = static_cast<std::uint8_t>(frame[0]);
  if (opcode != kMessageDataOpcode) {
    return error("bad-binary",
                 "unknown binary opcode " + std::to_string(opcode) + " (expected 1, messageData)");
  }
  if (frame.size() < kClientMessageHeaderBytes) {
    return error("bad-binary", "binary messageData of " + std::to_string(frame.size()) +
                                   " bytes is shorter than its 5-byte header");
  }
  return ClientMessageData{get_u32_le(frame.data() + 1), frame.substr(kClientMessageHeaderBytes)};
}

std::array<char, kMessageDataHeaderBytes> message_data_header(SubscriptionId subscription,
                                                              std::uint64_t log_time_ns) {
  std::array<char, kMessageDataHeaderBytes> h{};
  h[0] = static_cast<char>(kMessageDataOpcode);
  put_u32(h.data() + 1, subscription);
  put_u64(h.data() + 5, log_time_ns);
  return h;
}

std::string encode_message_data(SubscriptionId subscription, std::uint64_t log_time_ns,
                                std::string_view payload) {
  const auto h = message_data_header(subscription, log_time_ns);
  std::string out(h.data(), h.size());
  out.append(payload);
  return out;
}

std::variant<MessageData, ProtocolError> decode_message_data(std::string_view frame) {
  if (frame.size() < kMessageDataHeaderBytes || static_cast<std::uint8_t>(frame[0]) != kMessageDataOpcode) {
    return error("bad-binary", "not a messageData frame (opcode 1 and a 13-byte header expected)");
  }
  return MessageData{get_u32_le(frame.data() + 1), get_u64_le(frame.data() + 5),
                     frame.substr(kMessageDataHeaderBytes)};
}

std::string encode_client_message_data(ClientChannelId channel, std::string_view payload) {
  std::string out(kClientMessageHeaderBytes, '\0');
  out[0] = static_cast<char>(kMessageDataOpcode);
  put_u32(out.data() + 1, channel);
  out.append(payload);
  return out;
}

std::string server_info_json(const ServerInfo& info) {
  json j = {{"op", "serverInfo"},
            {"name", info.name},
            {"capabilities", info.capabilities},
            {"supportedEncodings", info.supported_encodings},
            {"metadata", json::object()},
            {"sessionId", info.session_id}};
  for (const auto& [k, v] : info.metadata) j["metadata"][k] = v;
  return dump(j);
}

std::string advertise_json(const std::vector<Channel>& channels) {
  json arr = json::array();
  for (const auto& c : channels) {
    arr.push_back({{"id", c.id},
                   {"topic", c.spec.topic},
                   {"encoding", c.spec.encoding},
                   {"schemaName", c.spec.schema_name},
                   {"schemaEncoding", c.spec.schema_encoding},
                   {"schema", c.spec.schema}});
  }
  return dump({{"op", "advertise"}, {"channels", std::move(arr)}});
}

std::string unadvertise_json(const std::vector<ChannelId>& ids) {
  return dump({{"op", "unadvertise"}, {"channelIds", ids}});
}

std::string status_json(StatusLevel level, std::string_view message, std::string_view id) {
  return dump({{"op", "status"},
               {"level", static_cast<int>(level)},
               {"message", one_line(message, 512)},
               {"id", std::string(id)}});
}

}  // namespace mc::server
