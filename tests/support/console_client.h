#pragma once
/// @file
/// A console client of `microcobot serve` for the tests: the Foxglove WebSocket client
/// (ws_client.h) that knows the server's channels, subscribes to them, advertises the
/// console's two client channels and sends commands and actions (docs/console.md).

#include <cstdint>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "microcobot/server/foxglove_protocol.h"
#include "support/ws_client.h"

namespace mc::test {

/// A connected console client: knows the advertised channels, subscribes, publishes.
struct Console {
  WsClient ws;
  std::map<std::string, std::uint32_t> channels;  // topic -> channel id

  explicit Console(std::uint16_t port, const std::string& target = "/") {
    EXPECT_EQ(ws.connect(port, target), 101);
    // serverInfo, then the advertisement of the server's channels.
    for (int i = 0; i < 10 && channels.empty(); ++i) {
      const nlohmann::json j = ws.read_json();
      if (j.is_null()) break;
      if (j.value("op", "") == "advertise")
        for (const auto& c : j["channels"]) channels[c["topic"]] = c["id"];
    }
    EXPECT_GE(channels.size(), 4u);  // and the camera's three when there is one
    EXPECT_TRUE(ws.send_json({{"op", "advertise"},
                              {"channels",
                               {{{"id", 1},
                                 {"topic", "/console/command"},
                                 {"encoding", "json"},
                                 {"schemaName", "microcobot.Command"}},
                                {{"id", 2},
                                 {"topic", "/console/action"},
                                 {"encoding", "json"},
                                 {"schemaName", "microcobot.Action"}}}}}));
  }
  void subscribe_all() {
    nlohmann::json subs = nlohmann::json::array();
    std::uint32_t id = 10;
    for (const auto& [topic, ch] : channels) subs.push_back({{"id", id++}, {"channelId", ch}});
    EXPECT_TRUE(ws.send_json({{"op", "subscribe"}, {"subscriptions", subs}}));
  }
  void subscribe(const std::string& topic, std::uint32_t id) {
    EXPECT_TRUE(ws.send_json(
        {{"op", "subscribe"}, {"subscriptions", {{{"id", id}, {"channelId", channels.at(topic)}}}}}));
  }
  bool action(const std::string& name) {
    return ws.send(server::encode_client_message_data(2, nlohmann::json{{"action", name}}.dump()), true);
  }
  bool command(const nlohmann::json& c) {
    return ws.send(server::encode_client_message_data(1, c.dump()), true);
  }
  // The payload of the next message on subscription `id` (empty on timeout).
  std::string next_on(std::uint32_t id) {
    for (int i = 0; i < 100000; ++i) {
      const auto m = ws.read();
      if (!m) return {};
      if (m->text) continue;
      const auto d = server::decode_message_data(m->data);
      if (const auto* md = std::get_if<server::MessageData>(&d); md && md->subscription == id)
        return std::string(md->payload);
    }
    return {};
  }
};

}  // namespace mc::test
