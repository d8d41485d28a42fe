#include "microcobot/server/foxglove_protocol.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

namespace mc::server {
namespace {

using nlohmann::json;

template <typename T>
T expect_op(const ClientOp& op) {
  if (const auto* e = std::get_if<ProtocolError>(&op)) ADD_FAILURE() << e->id << ": " << e->message;
  const T* t = std::get_if<T>(&op);
  EXPECT_NE(t, nullptr);
  return t != nullptr ? *t : T{};
}

ProtocolError expect_error(const ClientOp& op) {
  const auto* e = std::get_if<ProtocolError>(&op);
  EXPECT_NE(e, nullptr);
  if (e == nullptr) return {};
  EXPECT_EQ(e->message.find('\n'), std::string::npos) << e->message;
  EXPECT_FALSE(e->message.empty());
  return *e;
}

TEST(FoxgloveProtocol, ParsesSubscribe) {
  const auto s = expect_op<SubscribeOp>(parse_client_text(
      R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":4294967295,"channelId":5}]})"));
  ASSERT_EQ(s.subscriptions.size(), 2u);
  EXPECT_EQ(s.subscriptions[0].id, 0u);
  EXPECT_EQ(s.subscriptions[0].channel, 3u);
  EXPECT_EQ(s.subscriptions[1].id, 4294967295u);
  EXPECT_EQ(s.subscriptions[1].channel, 5u);
}

TEST(FoxgloveProtocol, ParsesUnsubscribeAdvertiseUnadvertise) {
  const auto u =
      expect_op<UnsubscribeOp>(parse_client_text(R"({"op":"unsubscribe","subscriptionIds":[1,2]})"));
  EXPECT_EQ(u.subscription_ids, (std::vector<SubscriptionId>{1, 2}));
  const auto a = expect_op<ClientAdvertiseOp>(parse_client_text(
      R"({"op":"advertise","channels":[{"id":7,"topic":"/cmd","encoding":"json","schemaName":"Cmd"},)"
      R"({"id":8,"topic":"/x","encoding":"json"}]})"));
  ASSERT_EQ(a.channels.size(), 2u);
  EXPECT_EQ(a.channels[0].id, 7u);
  EXPECT_EQ(a.channels[0].topic, "/cmd");
  EXPECT_EQ(a.channels[0].encoding, "json");
  EXPECT_EQ(a.channels[0].schema_name, "Cmd");
  EXPECT_EQ(a.channels[1].schema_name, "");  // optional
  const auto ua =
      expect_op<ClientUnadvertiseOp>(parse_client_text(R"({"op":"unadvertise","channelIds":[7]})"));
  EXPECT_EQ(ua.channel_ids, (std::vector<ClientChannelId>{7}));
}

TEST(FoxgloveProtocol, RejectsMalformedJsonAndNonObjects) {
  EXPECT_EQ(expect_error(parse_client_text("{\"op\":")).id, "malformed-json");
  EXPECT_EQ(expect_error(parse_client_text("")).id, "malformed-json");
  EXPECT_EQ(expect_error(parse_client_text("[1,2]")).id, "malformed-json");
  EXPECT_EQ(expect_error(parse_client_text("42")).id, "malformed-json");
  // Deep nesting is refused before the parser sees it.
  EXPECT_EQ(expect_error(parse_client_text(std::string(100000, '['))).id, "malformed-json");
  // A newline in the input never reaches the one-line message.
  EXPECT_EQ(expect_error(parse_client_text("{\n\"op\"\n:\n")).id, "malformed-json");
}

TEST(FoxgloveProtocol, RejectsUnknownAndUnsupportedOps) {
  EXPECT_EQ(expect_error(parse_client_text(R"({"op":"explode"})")).id, "unknown-op");
  EXPECT_EQ(expect_error(parse_client_text(R"({"op":"getParameters","parameterNames":[]})")).id,
            "unsupported-op");
  EXPECT_EQ(expect_error(parse_client_text(R"({"subscriptions":[]})")).id, "bad-field");
  EXPECT_EQ(expect_error(parse_client_text(R"({"op":7})")).id, "bad-field");
  const auto e = expect_error(parse_client_text("{\"op\":\"a\\nb\"}"));
  EXPECT_EQ(e.id, "unknown-op");
}

TEST(FoxgloveProtocol, RejectsWrongFieldTypes) {
  const char* bad[] = {
      R"({"op":"subscribe"})",
      R"({"op":"subscribe","subscriptions":{}})",
      R"({"op":"subscribe","subscriptions":[1]})",
      R"({"op":"subscribe","subscriptions":[{"id":"1","channelId":1}]})",
      R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":1}]})",
      R"({"op":"subscribe","subscriptions":[{"id":1.5,"channelId":1}]})",
      R"({"op":"subscribe","subscriptions":[{"id":4294967296,"channelId":1}]})",
      R"({"op":"subscribe","subscriptions":[{"id":1}]})",
      R"({"op":"unsubscribe","subscriptionIds":["a"]})",
      R"({"op":"unsubscribe","subscriptionIds":null})",
      R"({"op":"advertise","channels":[{"id":1,"topic":5,"encoding":"json"}]})",
      R"({"op":"advertise","channels":[{"id":1,"encoding":"json"}]})",
      R"({"op":"advertise","channels":[{"id":1,"topic":"/t","encoding":"json","schemaName":[]}]})",
      R"({"op":"unadvertise","channelIds":[true]})",
  };
  for (const char* text : bad) {
    SCOPED_TRACE(text);
    EXPECT_EQ(expect_error(parse_client_text(text)).id, "bad-field");
  }
  const auto e =
      expect_error(parse_client_text(R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":"x"}]})"));
  EXPECT_NE(e.message.find("subscriptions[0].channelId"), std::string::npos) << e.message;
}

TEST(FoxgloveProtocol, ClientBinaryMessageData) {
  const std::string frame = encode_client_message_data(0x01020304u, R"({"v":1})");
  ASSERT_EQ(frame.size(), 5u + 7u);
  EXPECT_EQ(static_cast<unsigned char>(frame[1]), 0x04);  // little-endian
  const auto parsed = parse_client_binary(frame);
  const auto* d = std::get_if<ClientMessageData>(&parsed);
  ASSERT_NE(d, nullptr);
  EXPECT_EQ(d->channel, 0x01020304u);
  EXPECT_EQ(d->payload, R"({"v":1})");
  // Header only: an empty payload is a message.
  const auto empty = parse_client_binary(encode_client_message_data(9, ""));
  ASSERT_NE(std::get_if<ClientMessageData>(&empty), nullptr);
}

TEST(FoxgloveProtocol, ClientBinaryGarbage) {
  for (const std::string& frame : {std::string(), std::string("\x01\x02", 2),
                                   std::string("\x02\x00\x00\x00\x00", 5), std::string("\xff garbage")}) {
    const auto parsed = parse_client_binary(frame);
    const auto* e = std::get_if<ProtocolError>(&parsed);
    ASSERT_NE(e, nullptr);
    EXPECT_EQ(e->id, "bad-binary");
  }
}

TEST(FoxgloveProtocol, ServerMessageDataRoundTrip) {
  const std::uint64_t t = 0x0102030405060708ull;
  const std::string frame = encode_message_data(42, t, "payload");
  ASSERT_EQ(frame.size(), 13u + 7u);
  EXPECT_EQ(frame[0], 0x01);
  EXPECT_EQ(static_cast<unsigned char>(frame[1]), 42);
  EXPECT_EQ(static_cast<unsigned char>(frame[5]), 0x08);   // u64 LE, low byte first
  EXPECT_EQ(static_cast<unsigned char>(frame[12]), 0x01);  // high byte last
  const auto h = message_data_header(42, t);
  EXPECT_EQ(std::string(h.data(), h.size()), frame.substr(0, 13));
  const auto d = decode_message_data(frame);
  ASSERT_TRUE(std::holds_alternative<MessageData>(d));
  EXPECT_EQ(std::get<MessageData>(d).subscription, 42u);
  EXPECT_EQ(std::get<MessageData>(d).log_time_ns, t);
  EXPECT_EQ(std::get<MessageData>(d).payload, "payload");
  EXPECT_TRUE(std::holds_alternative<ProtocolError>(decode_message_data("\x01short")));
}

TEST(FoxgloveProtocol, ServerInfoAdvertiseStatusJson) {
  ServerInfo info;
  info.name = "microcobot";
  info.metadata = {{"version", "0.1"}};
  info.session_id = "123";
  const json si = json::parse(server_info_json(info));
  EXPECT_EQ(si["op"], "serverInfo");
  EXPECT_EQ(si["name"], "microcobot");
  EXPECT_EQ(si["capabilities"], json::array({"clientPublish"}));
  EXPECT_EQ(si["supportedEncodings"], json::array({"json"}));
  EXPECT_EQ(si["metadata"]["version"], "0.1");
  EXPECT_EQ(si["sessionId"], "123");

  const json adv = json::parse(advertise_json({Channel{3, {"/state", "json", "State", "jsonschema", "{}"}}}));
  EXPECT_EQ(adv["op"], "advertise");
  ASSERT_EQ(adv["channels"].size(), 1u);
  EXPECT_EQ(adv["channels"][0]["id"], 3);
  EXPECT_EQ(adv["channels"][0]["topic"], "/state");
  EXPECT_EQ(adv["channels"][0]["encoding"], "json");
  EXPECT_EQ(adv["channels"][0]["schemaName"], "State");
  EXPECT_EQ(adv["channels"][0]["schemaEncoding"], "jsonschema");
  EXPECT_EQ(adv["channels"][0]["schema"], "{}");
  EXPECT_EQ(json::parse(advertise_json({}))["channels"], json::array());
  EXPECT_EQ(json::parse(unadvertise_json({1, 2}))["channelIds"], json::array({1, 2}));

  // Status: one line, bounded, valid JSON even for invalid UTF-8.
  const json st =
      json::parse(status_json(StatusLevel::kWarning, "two\nlines \xff" + std::string(2000, 'x'), "rate"));
  EXPECT_EQ(st["op"], "status");
  EXPECT_EQ(st["level"], 1);
  EXPECT_EQ(st["id"], "rate");
  const std::string msg = st["message"];
  EXPECT_EQ(msg.find('\n'), std::string::npos);
  EXPECT_LT(msg.size(), 600u);
}

}  // namespace
}  // namespace mc::server
