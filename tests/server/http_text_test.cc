#include "microcobot/server/http_text.h"

#include <gtest/gtest.h>

#include <string>

namespace mc::server {
namespace {

TEST(HttpText, ConstantTimeEqualIsPlainEquality) {
  EXPECT_TRUE(constant_time_equal("s3cr3t", "s3cr3t"));
  EXPECT_TRUE(constant_time_equal("", ""));
  EXPECT_FALSE(constant_time_equal("s3cr3t", "s3cr3T"));
  EXPECT_FALSE(constant_time_equal("s3cr3t", "s3cr3"));    // a prefix
  EXPECT_FALSE(constant_time_equal("s3cr3t", "s3cr3tx"));  // longer
  EXPECT_FALSE(constant_time_equal("s3cr3t", ""));
  EXPECT_FALSE(constant_time_equal("", "x"));
  EXPECT_FALSE(constant_time_equal(std::string("a\0b", 3), std::string("a\0c", 3)));
}

TEST(HttpText, PercentDecodes) {
  EXPECT_EQ(percent_decode("s3cr3t%2F%2b"), "s3cr3t/+");
  EXPECT_EQ(percent_decode("a+b"), "a b");
  EXPECT_EQ(percent_decode("%41%"), "A%");    // a lone '%' is kept
  EXPECT_EQ(percent_decode("%4"), "%4");      // one digit only
  EXPECT_EQ(percent_decode("%zz1"), "%zz1");  // not hex
  EXPECT_EQ(percent_decode("%00").size(), 1u);
  EXPECT_EQ(percent_decode(""), "");
}

TEST(HttpText, ReadsAQueryParameter) {
  EXPECT_EQ(query_param("/?token=abc", "token"), "abc");
  EXPECT_EQ(query_param("/x?a=1&token=s%2F&b=2", "token"), "s/");
  EXPECT_EQ(query_param("/?token=first&token=second", "token"), "first");
  EXPECT_EQ(query_param("/?token", "token"), "");
  EXPECT_EQ(query_param("/?token=", "token"), "");
  EXPECT_EQ(query_param("/?tok=abc", "token"), std::nullopt);
  EXPECT_EQ(query_param("/?tokens=abc", "token"), std::nullopt);
  EXPECT_EQ(query_param("/token=abc", "token"), std::nullopt);  // no query
  EXPECT_EQ(query_param("/?", "token"), std::nullopt);
}

TEST(HttpText, FindsTheFoxgloveSubprotocolInTheOffer) {
  EXPECT_TRUE(offers_subprotocol("foxglove.websocket.v1"));
  EXPECT_TRUE(offers_subprotocol("chat, foxglove.websocket.v1"));
  EXPECT_TRUE(offers_subprotocol(" \tfoxglove.websocket.v1\t ,chat"));
  EXPECT_FALSE(offers_subprotocol(""));
  EXPECT_FALSE(offers_subprotocol("chat"));
  EXPECT_FALSE(offers_subprotocol("foxglove.websocket.v1x"));
  EXPECT_FALSE(offers_subprotocol("foxglove.websocket.v1;q=1"));
}

}  // namespace
}  // namespace mc::server
