// The server over loopback with the tests' small Foxglove client (support/ws_client.h).
#include "microcobot/server/foxglove_server.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "microcobot/core/error.h"
#include "support/ws_client.h"

namespace mc::server {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

constexpr auto kTimeout = test::kClientTimeout;

ServerOptions loopback() {
  ServerOptions o;
  o.port = 0;
  return o;
}

using Client = test::WsClient;
using test::http_request;

template <typename Pred>
bool eventually(Pred pred, std::chrono::milliseconds timeout = 3000ms) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (pred()) return true;
    std::this_thread::sleep_for(5ms);
  }
  return pred();
}

ChannelSpec spec(const std::string& topic) {
  ChannelSpec s;
  s.topic = topic;
  s.schema_name = "mc.Test";
  s.schema = R"({"type":"object"})";
  return s;
}

TEST(FoxgloveServer, HandshakeSendsServerInfoThenAdvertise) {
  FoxgloveServer server(loopback(), "test server");
  const ChannelId a = server.add_channel(spec("/a"));
  const ChannelId b = server.add_channel(spec("/b"));
  server.set_metadata({{"kind", "test"}});
  server.start();
  ASSERT_NE(server.port(), 0);

  Client c;
  ASSERT_EQ(c.connect(server.port()), 101);
  EXPECT_EQ(c.response_header("Sec-WebSocket-Protocol"), "foxglove.websocket.v1");
  const json info = c.read_json();
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_EQ(info["name"], "test server");
  EXPECT_EQ(info["capabilities"], json::array({"clientPublish"}));
  EXPECT_EQ(info["supportedEncodings"], json::array({"json"}));
  EXPECT_EQ(info["metadata"]["kind"], "test");
  EXPECT_FALSE(info["sessionId"].get<std::string>().empty());
  const json adv = c.read_json();
  EXPECT_EQ(adv["op"], "advertise");
  ASSERT_EQ(adv["channels"].size(), 2u);
  EXPECT_EQ(adv["channels"][0]["id"], a);
  EXPECT_EQ(adv["channels"][0]["topic"], "/a");
  EXPECT_EQ(adv["channels"][1]["id"], b);
  EXPECT_TRUE(eventually([&] { return server.client_count() == 1; }));

  // A channel added later is advertised to the connected client.
  const ChannelId late = server.add_channel(spec("/late"));
  const json adv2 = c.read_json();
  EXPECT_EQ(adv2["op"], "advertise");
  ASSERT_EQ(adv2["channels"].size(), 1u);
  EXPECT_EQ(adv2["channels"][0]["id"], late);
  EXPECT_EQ(adv2["channels"][0]["topic"], "/late");

  // The application's own status reaches the client.
  server.send_status(1, StatusLevel::kInfo, "hello", "greeting");
  const json st = c.read_status("greeting");
  EXPECT_EQ(st["level"], 0);
  EXPECT_EQ(st["message"], "hello");
}

TEST(FoxgloveServer, UpgradeWithoutSubprotocolIs400) {
  FoxgloveServer server(loopback(), "s");
  server.start();
  Client c;
  EXPECT_EQ(c.connect(server.port(), "/", /*subprotocol=*/false), 400);
  EXPECT_EQ(server.client_count(), 0u);
}

TEST(FoxgloveServer, SubscribersReceiveMessageData) {
  FoxgloveServer server(loopback(), "s");
  const ChannelId ch = server.add_channel(spec("/state"));
  const ChannelId other = server.add_channel(spec("/other"));
  server.start();
  Client c;
  ASSERT_EQ(c.connect(server.port()), 101);
  c.read_json();  // serverInfo
  c.read_json();  // advertise
  ASSERT_TRUE(c.send_json({{"op", "subscribe"}, {"subscriptions", {{{"id", 7}, {"channelId", ch}}}}}));
  ASSERT_TRUE(c.sync());

  server.publish(other, 1, "not subscribed");
  for (std::uint64_t i = 0; i < 3; ++i) {
    server.publish(ch, 1000000000ull * 1700000000ull + i, "{\"i\":" + std::to_string(i) + "}");
  }
  for (std::uint64_t i = 0; i < 3; ++i) {
    const auto m = c.read();
    ASSERT_TRUE(m);
    ASSERT_FALSE(m->text);
    const auto d = decode_message_data(m->data);
    ASSERT_TRUE(std::holds_alternative<MessageData>(d));
    EXPECT_EQ(std::get<MessageData>(d).subscription, 7u);
    EXPECT_EQ(std::get<MessageData>(d).log_time_ns, 1000000000ull * 1700000000ull + i);
    EXPECT_EQ(std::get<MessageData>(d).payload, "{\"i\":" + std::to_string(i) + "}");
  }
  // A reused subscription id or a second subscription of the channel is refused.
  ASSERT_TRUE(c.send_json({{"op", "subscribe"}, {"subscriptions", {{{"id", 7}, {"channelId", other}}}}}));
  EXPECT_EQ(c.read_status("bad-subscription")["level"], 2);
  // After unsubscribing nothing more arrives: the next message is the sync status.
  ASSERT_TRUE(c.send_json({{"op", "unsubscribe"}, {"subscriptionIds", {7}}}));
  ASSERT_TRUE(c.sync());
  server.publish(ch, 5, "late");
  ASSERT_TRUE(c.send_json({{"op", "unsubscribe"}, {"subscriptionIds", {7}}}));
  const auto next = c.read();
  ASSERT_TRUE(next);
  EXPECT_TRUE(next->text);
  EXPECT_EQ(json::parse(next->data)["id"], "unknown-subscription");
  EXPECT_GT(server.counters().bytes_sent, 0u);
}

TEST(FoxgloveServer, ClientPublishReachesTheCallback) {
  FoxgloveServer server(loopback(), "s");
  std::mutex mu;
  std::condition_variable cv;
  std::vector<std::tuple<ClientId, std::string, std::string, std::string>> got;
  std::atomic<ClientId> connected{0};
  server.on_connect([&](ClientId id) { connected = id; });
  server.on_client_message([&](const ClientMessage& m) {
    std::lock_guard lk(mu);
    got.emplace_back(m.client, std::string(m.topic), std::string(m.schema_name), std::string(m.payload));
    cv.notify_all();
  });
  server.start();
  Client c;
  ASSERT_EQ(c.connect(server.port()), 101);
  ASSERT_TRUE(c.send_json(
      {{"op", "advertise"},
       {"channels", {{{"id", 5}, {"topic", "/cmd"}, {"encoding", "json"}, {"schemaName", "Cmd"}}}}}));
  ASSERT_TRUE(c.send(encode_client_message_data(5, R"({"v":1.5})"), /*binary=*/true));
  {
    std::unique_lock lk(mu);
    ASSERT_TRUE(cv.wait_for(lk, kTimeout, [&] { return !got.empty(); }));
    EXPECT_EQ(std::get<0>(got[0]), connected.load());
    EXPECT_EQ(std::get<1>(got[0]), "/cmd");
    EXPECT_EQ(std::get<2>(got[0]), "Cmd");
    EXPECT_EQ(std::get<3>(got[0]), R"({"v":1.5})");
  }
  // Only json channels; only advertised channels; unadvertise ends a channel.
  ASSERT_TRUE(c.send_json(
      {{"op", "advertise"},
       {"channels", {{{"id", 6}, {"topic", "/p"}, {"encoding", "protobuf"}, {"schemaName", "P"}}}}}));
  EXPECT_EQ(c.read_status("unsupported-encoding")["level"], 2);
  ASSERT_TRUE(c.send(encode_client_message_data(6, "{}"), true));
  EXPECT_EQ(c.read_status("unknown-channel")["level"], 2);
  ASSERT_TRUE(c.send_json({{"op", "unadvertise"}, {"channelIds", {5}}}));
  ASSERT_TRUE(c.send(encode_client_message_data(5, "{}"), true));
  EXPECT_EQ(c.read_status("unknown-channel")["level"], 2);
  std::lock_guard lk(mu);
  EXPECT_EQ(got.size(), 1u);
}

TEST(FoxgloveServer, BadInputGetsErrorStatusAndTheServerKeepsServing) {
  ServerOptions o = loopback();
  FoxgloveServer server(o, "s");
  const ChannelId ch = server.add_channel(spec("/state"));
  server.start();
  Client c;
  ASSERT_EQ(c.connect(server.port()), 101);
  struct Case {
    std::string data;
    bool binary;
    std::string id;
  };
  const std::vector<Case> cases = {
      {"{not json", false, "malformed-json"},
      {R"({"op":"fly"})", false, "unknown-op"},
      {R"({"op":"subscribe","subscriptions":[{"id":"x","channelId":1}]})", false, "bad-field"},
      {R"({"op":"subscribe","subscriptions":[{"id":1,"channelId":999}]})", false, "unknown-channel"},
      {R"({"op":"unsubscribe","subscriptionIds":[12345]})", false, "unknown-subscription"},
      {std::string("\x07garbage"), true, "bad-binary"},
      {std::string("\x01\x02", 2), true, "bad-binary"},
      {std::string(1 << 20, 'x'), false, "oversized"},
      {std::string(1 << 20, '\x01'), true, "oversized"},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.id);
    ASSERT_TRUE(c.send(k.data, k.binary));
    const json st = c.read_status(k.id);
    ASSERT_FALSE(st.is_null());
    EXPECT_EQ(st["level"], 2);
    const std::string msg = st["message"];
    EXPECT_EQ(msg.find('\n'), std::string::npos);
  }
  EXPECT_GE(server.counters().messages_rejected, cases.size());

  // The same client still works...
  ASSERT_TRUE(c.send_json({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", ch}}}}}));
  ASSERT_TRUE(c.sync());
  server.publish(ch, 3, "{}");
  const auto m = c.read();
  ASSERT_TRUE(m);
  EXPECT_FALSE(m->text);
  // ...and so does a second one.
  Client d;
  ASSERT_EQ(d.connect(server.port()), 101);
  EXPECT_EQ(d.read_json()["op"], "serverInfo");
}

TEST(FoxgloveServer, TokenIsRequiredOnTheUpgrade) {
  ServerOptions o = loopback();
  o.token = "s3cr3t/+";
  FoxgloveServer server(o, "s", {{"/", {"text/html", "<p>hi</p>"}}});
  server.start();
  for (const std::string target :
       {"/", "/?token=", "/?token=s3cr3t", "/?token=s3cr3t%2F%2Bx", "/?tok=s3cr3t%2F%2B"}) {
    SCOPED_TRACE(target);
    Client c;
    EXPECT_EQ(c.connect(server.port(), target), 401);
  }
  Client ok;
  EXPECT_EQ(ok.connect(server.port(), "/?a=1&token=s3cr3t%2F%2B"), 101);
  EXPECT_EQ(ok.read_json()["op"], "serverInfo");
  // The HTTP resources do not need it.
  EXPECT_EQ(http_request(server.port(), "GET", "/").status, 200);
}

TEST(FoxgloveServer, ConnectionsBeyondTheLimitGet503ThenRecover) {
  ServerOptions o = loopback();
  o.max_connections = 2;
  FoxgloveServer server(o, "s");
  server.start();
  Client a, b;
  ASSERT_EQ(a.connect(server.port()), 101);
  ASSERT_EQ(b.connect(server.port()), 101);
  {
    Client c;
    EXPECT_EQ(c.connect(server.port()), 503);
  }
  EXPECT_EQ(http_request(server.port(), "GET", "/").status, 503);
  EXPECT_GE(server.counters().connections_refused, 2u);
  a.close();
  // Once a slot is free a new client gets in.
  const bool recovered = eventually([&] {
    Client d;
    return d.connect(server.port()) == 101;
  });
  EXPECT_TRUE(recovered);
}

TEST(FoxgloveServer, FloodIsRateLimited) {
  ServerOptions o = loopback();
  o.max_client_messages_per_s = 2000;
  FoxgloveServer server(o, "s");
  const ChannelId ch = server.add_channel(spec("/state"));
  std::atomic<int> handled{0};
  server.on_client_message([&](const ClientMessage&) { ++handled; });
  server.start();
  Client c;
  ASSERT_EQ(c.connect(server.port()), 101);
  ASSERT_TRUE(c.send_json(
      {{"op", "advertise"}, {"channels", {{{"id", 1}, {"topic", "/cmd"}, {"encoding", "json"}}}}}));
  const std::string msg = encode_client_message_data(1, R"({"v":1})");
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 10000; ++i) ASSERT_TRUE(c.send(msg, true));
  const json warn = c.read_status("rate-limit");
  ASSERT_FALSE(warn.is_null());
  EXPECT_EQ(warn["level"], 1);
  ASSERT_TRUE(eventually([&] { return server.counters().messages_received >= 10001; }, 5000ms));
  const double burst_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The server still answers this client (once its bucket refills) and others.
  std::this_thread::sleep_for(50ms);
  ASSERT_TRUE(c.send_json({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", ch}}}}}));
  ASSERT_TRUE(c.sync());
  Client d;
  ASSERT_EQ(d.connect(server.port()), 101);
  // At most one bucket (2000) plus the refill during the burst got through.
  EXPECT_LT(handled.load(), 2000 + 2000 * burst_s + 10);
  EXPECT_GE(handled.load(), 1000);
  EXPECT_GT(server.counters().messages_rejected, 10000 - 2000 - 2000 * burst_s - 10);
}

TEST(FoxgloveServer, SlowClientDoesNotBlockPublish) {
  ServerOptions o = loopback();
  FoxgloveServer server(o, "s");
  const ChannelId ch = server.add_channel(spec("/big"));
  server.start();
  Client slow;
  ASSERT_EQ(slow.connect(server.port()), 101);
  ASSERT_TRUE(slow.send_json({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", ch}}}}}));
  ASSERT_TRUE(slow.sync());
  // The client now reads nothing while 100 MB are published at it.
  const std::string payload(10 * 1024, 'p');
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 10000; ++i) server.publish(ch, static_cast<std::uint64_t>(i), payload);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 10.0) << "publish waited for the client (blocked, it would wait forever)";
  const ServerCounters k = server.counters();
  EXPECT_GT(k.messages_dropped, 5000u);  // at most 4 MB queued plus the socket buffers
  // The first message is still the oldest undropped one: the stream is intact.
  const auto m = slow.read();
  ASSERT_TRUE(m);
  EXPECT_FALSE(m->text);
  EXPECT_TRUE(std::holds_alternative<MessageData>(decode_message_data(m->data)));
  const auto t1 = std::chrono::steady_clock::now();
  server.stop();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count(), 2.0);
}

TEST(FoxgloveServer, ALatestOnlyChannelGivesASlowClientTheNewestMessageNotAQueue) {
  // A camera's images: a slow viewer should see the newest one. With the client reading nothing,
  // each new message replaces the one still queued for it; once it reads, what comes is the
  // tail of the stream (the sockets' buffers, then the newest), never the whole backlog.
  FoxgloveServer server(loopback(), "s");
  ChannelSpec images = spec("/camera");
  images.latest_only = true;
  const ChannelId ch = server.add_channel(images);
  server.start();
  Client slow;
  ASSERT_EQ(slow.connect(server.port()), 101);
  ASSERT_TRUE(slow.send_json({{"op", "subscribe"}, {"subscriptions", {{{"id", 1}, {"channelId", ch}}}}}));
  ASSERT_TRUE(slow.sync());
  const int n = 2000;
  for (int i = 0; i < n; ++i) server.publish(ch, static_cast<std::uint64_t>(i), std::string(10 * 1024, 'a'));
  const ServerCounters k = server.counters();
  EXPECT_GT(k.messages_superseded, 1000u) << "the queue held more than one image";
  EXPECT_EQ(k.messages_dropped, 0u) << "the queue never reached its byte limit";
  // Read until the newest arrives: it does, and fewer than half the messages came before it.
  int got = 0;
  std::uint64_t last = 0;
  while (last != static_cast<std::uint64_t>(n - 1)) {
    const auto m = slow.read();
    ASSERT_TRUE(m);
    const auto d = decode_message_data(m->data);
    ASSERT_TRUE(std::holds_alternative<MessageData>(d));
    last = std::get<MessageData>(d).log_time_ns;
    ++got;
  }
  EXPECT_LT(got, n / 2);
  server.stop();
}

TEST(FoxgloveServer, HttpResources) {
  FoxgloveServer server(loopback(), "s",
                        {{"/", {"text/html; charset=utf-8", "<!doctype html><p>console</p>"}},
                         {"/app.js", {"text/javascript", "console.log(1);"}}});
  server.start();
  const auto index = http_request(server.port(), "GET", "/");
  EXPECT_EQ(index.status, 200);
  EXPECT_EQ(index.body, "<!doctype html><p>console</p>");
  EXPECT_EQ(index.header("Content-Type"), "text/html; charset=utf-8");
  EXPECT_EQ(index.header("Cache-Control"), "no-store");
  EXPECT_EQ(index.header("Content-Length"), std::to_string(index.body.size()));
  EXPECT_EQ(http_request(server.port(), "GET", "/app.js?v=2").body, "console.log(1);");

  const auto missing = http_request(server.port(), "GET", "/nope");
  EXPECT_EQ(missing.status, 404);
  EXPECT_EQ(missing.body, "not found: /nope\n");
  const auto post = http_request(server.port(), "POST", "/");
  EXPECT_EQ(post.status, 405);
  EXPECT_EQ(post.header("Allow"), "GET, HEAD");
  EXPECT_EQ(http_request(server.port(), "GET", "/", std::string(10000, 'h')).status, 431);
}

TEST(FoxgloveServer, StopWithConnectedClientsIsPrompt) {
  auto server = std::make_unique<FoxgloveServer>(loopback(), "s");
  std::atomic<int> disconnected{0};
  server->on_disconnect([&](ClientId) { ++disconnected; });
  server->start();
  std::vector<std::unique_ptr<Client>> clients;
  for (int i = 0; i < 3; ++i) {
    clients.push_back(std::make_unique<Client>());
    ASSERT_EQ(clients.back()->connect(server->port()), 101);
  }
  ASSERT_TRUE(eventually([&] { return server->client_count() == 3; }));
  const auto t0 = std::chrono::steady_clock::now();
  server->stop();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_EQ(server->client_count(), 0u);
  EXPECT_EQ(disconnected.load(), 3);
  server->stop();  // idempotent
  server.reset();
  // The clients see the connection end.
  for (auto& c : clients) {
    for (int i = 0; i < 3; ++i) {
      if (!c->read(1000ms)) break;
    }
  }
}

TEST(FoxgloveServer, StartFailsWithOneLineErrors) {
  ServerOptions bad = loopback();
  bad.address = "not-an-address";
  FoxgloveServer s1(bad, "s");
  EXPECT_THROW(s1.start(), mc::InvalidParams);

  FoxgloveServer first(loopback(), "s");
  first.start();
  ServerOptions same = loopback();
  same.port = first.port();
  FoxgloveServer second(same, "s");
  try {
    second.start();
    FAIL() << "binding a used port succeeded";
  } catch (const mc::Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("127.0.0.1:" + std::to_string(first.port())), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos);
  }
  ServerOptions invalid = loopback();
  invalid.max_connections = 0;
  EXPECT_THROW(FoxgloveServer(invalid, "s"), mc::InvalidParams);
}

}  // namespace
}  // namespace mc::server
