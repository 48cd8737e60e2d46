#include "pipelines/live/request_guard.h"

#include <cctype>
#include <regex>

namespace portcal {
namespace {

constexpr const char* kCookieName = "portcal_live_token";

// Host and port of a Host header ("1.2.3.4:8080", "[::1]:8080",
// "localhost"); port -1 where none is given.
bool SplitHost(const std::string& header, std::string* host, int* port) {
  static const std::regex pattern(R"(^(\[[0-9A-Fa-f:.]+\]|[^:\[\]]+)(?::([0-9]{1,5}))?$)");
  std::smatch match;
  if (!std::regex_match(header, match, pattern)) return false;
  *host = match[1];
  *port = match[2].matched ? std::stoi(match[2]) : -1;
  return true;
}

bool IsIpLiteralOrLocalhost(const std::string& host) {
  static const std::regex ipv4(
      R"(^(25[0-5]|2[0-4][0-9]|1?[0-9]?[0-9])(\.(25[0-5]|2[0-4][0-9]|1?[0-9]?[0-9])){3}$)");
  if (host == "localhost" || std::regex_match(host, ipv4)) return true;
  return host.size() > 2 && host.front() == '[' && host.back() == ']';
}

std::string CookieValue(const std::string& cookies, const std::string& name) {
  size_t at = 0;
  while (at < cookies.size()) {
    const size_t end = std::min(cookies.find(';', at), cookies.size());
    std::string pair = cookies.substr(at, end - at);
    pair.erase(0, pair.find_first_not_of(' '));
    if (pair.compare(0, name.size() + 1, name + "=") == 0) return pair.substr(name.size() + 1);
    at = end + 1;
  }
  return "";
}

}  // namespace

std::optional<std::string> RefuseLiveRequest(const LiveRequest& request, int port,
                                             const std::string& token) {
  std::string host;
  int host_port = -1;
  if (!SplitHost(request.host, &host, &host_port) || !IsIpLiteralOrLocalhost(host)) {
    return "Host '" + request.host + "' is not this page's address (open it by its IP address)";
  }
  // Browsers always name a port other than 80; some clients name none.
  if (host_port != -1 && host_port != port) return "Host '" + request.host + "' names another port";
  if (request.method != "GET" && request.method != "HEAD") {
    if (!request.origin.empty() && request.origin != "http://" + request.host) {
      return "a command from another page (Origin " + request.origin + ")";
    }
    if (!request.sec_fetch_site.empty() && request.sec_fetch_site != "same-origin" &&
        request.sec_fetch_site != "none") {
      return "a command from another site (Sec-Fetch-Site " + request.sec_fetch_site + ")";
    }
  }
  if (!token.empty() && request.token_param != token &&
      CookieValue(request.cookie, kCookieName) != token) {
    return "no valid token (open the address portcal printed, with its ?token=)";
  }
  return std::nullopt;
}

std::string LiveTokenCookie(const std::string& token) {
  return std::string(kCookieName) + "=" + token + "; Path=/; HttpOnly; SameSite=Strict";
}

bool IsValidLiveToken(const std::string& token) {
  if (token.size() < 16 || token.size() > 128) return false;
  for (const char c : token) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') return false;
  }
  return true;
}

}  // namespace portcal
