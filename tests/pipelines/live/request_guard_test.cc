// The live page's guard, request by request: its own Host (an IP literal or
// localhost, its port) and Origin only for commands, the token when set.
#include "pipelines/live/request_guard.h"

#include <gtest/gtest.h>

namespace portcal {
namespace {

LiveRequest Request(const std::string& method, const std::string& host,
                    const std::string& origin = "") {
  LiveRequest request;
  request.method = method;
  request.host = host;
  request.origin = origin;
  return request;
}

TEST(RequestGuard, OnlyThePagesOwnHost) {
  EXPECT_FALSE(RefuseLiveRequest(Request("GET", "127.0.0.1:8080"), 8080, ""));
  EXPECT_FALSE(RefuseLiveRequest(Request("GET", "localhost:8080"), 8080, ""));
  EXPECT_FALSE(RefuseLiveRequest(Request("GET", "192.168.1.20:8080"), 8080,
                                 ""));  // 0.0.0.0, from the tether
  EXPECT_FALSE(RefuseLiveRequest(Request("GET", "[::1]:8080"), 8080, ""));
  EXPECT_FALSE(
      RefuseLiveRequest(Request("GET", "127.0.0.1"), 8080, ""));  // a client naming no port
  // DNS rebinding: a name of the attacker's resolving to this machine.
  EXPECT_TRUE(RefuseLiveRequest(Request("GET", "evil.example:8080"), 8080, ""));
  EXPECT_TRUE(RefuseLiveRequest(Request("GET", "127.0.0.1.evil.example:8080"), 8080, ""));
  EXPECT_TRUE(RefuseLiveRequest(Request("GET", "127.0.0.1:8081"), 8080, ""));
  EXPECT_TRUE(RefuseLiveRequest(Request("GET", ""), 8080, ""));
  EXPECT_TRUE(RefuseLiveRequest(Request("GET", "300.1.1.1:8080"), 8080, ""));
}

TEST(RequestGuard, CommandsOnlyFromThePage) {
  EXPECT_FALSE(
      RefuseLiveRequest(Request("POST", "127.0.0.1:8080", "http://127.0.0.1:8080"), 8080, ""));
  EXPECT_FALSE(RefuseLiveRequest(Request("POST", "127.0.0.1:8080"), 8080, ""));  // curl: no Origin
  const auto refused =
      RefuseLiveRequest(Request("POST", "127.0.0.1:8080", "http://evil.example"), 8080, "");
  ASSERT_TRUE(refused);
  EXPECT_NE(refused->find("another page (Origin http://evil.example)"), std::string::npos)
      << *refused;
  EXPECT_TRUE(
      RefuseLiveRequest(Request("POST", "127.0.0.1:8080", "null"), 8080, ""));  // a file:// page
  LiveRequest cross = Request("POST", "127.0.0.1:8080");
  cross.sec_fetch_site = "cross-site";
  EXPECT_TRUE(RefuseLiveRequest(cross, 8080, ""));
  // Reading is left to the browser's same-origin policy, which keeps the
  // answer from other pages.
  EXPECT_FALSE(
      RefuseLiveRequest(Request("GET", "127.0.0.1:8080", "http://evil.example"), 8080, ""));
}

TEST(RequestGuard, TheTokenWhenSet) {
  const std::string token = "s3cret-token_1234";
  ASSERT_TRUE(IsValidLiveToken(token));
  EXPECT_FALSE(IsValidLiveToken("short"));
  EXPECT_FALSE(IsValidLiveToken("has space in it 12345"));
  LiveRequest request = Request("GET", "127.0.0.1:8080");
  EXPECT_TRUE(RefuseLiveRequest(request, 8080, token));
  request.token_param = token;
  EXPECT_FALSE(RefuseLiveRequest(request, 8080, token));
  request.token_param = "";
  const std::string cookie = LiveTokenCookie(token);
  request.cookie = "other=1; " + cookie.substr(0, cookie.find(';'));
  EXPECT_FALSE(RefuseLiveRequest(request, 8080, token));
  request.cookie = "portcal_live_token=wrong";
  EXPECT_TRUE(RefuseLiveRequest(request, 8080, token));
}

}  // namespace
}  // namespace portcal
