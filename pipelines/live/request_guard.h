// Who may use the live page: a local web UI obeys only its own page. A page
// the operator opens in another tab (a foreign Origin), a DNS-rebinding
// name pointing at this machine (a foreign Host), or, with --Live.token, a
// client without the token is refused before any handler runs.
#pragma once

#include <optional>
#include <string>

namespace portcal {

struct LiveRequest {
  std::string method;          // "GET", "POST", ...
  std::string host;            // the Host header
  std::string origin;          // the Origin header, "" when absent
  std::string sec_fetch_site;  // the browser's Sec-Fetch-Site, "" when absent
  std::string cookie;          // the Cookie header
  std::string token_param;     // the ?token= query parameter
};

// Why the request is refused, or nothing. Host must be an IP literal (v4,
// or v6 in brackets) or "localhost" with the served `port`: a name is
// what DNS rebinding uses. A state-changing request (anything but GET and
// HEAD) from a browser must come from the page itself: an Origin, where
// sent, of http://<Host>, and a Sec-Fetch-Site, where sent, of same-origin
// or none. With a `token`, the request carries it (?token= or the cookie
// the page set).
std::optional<std::string> RefuseLiveRequest(const LiveRequest& request, int port,
                                             const std::string& token);

// The cookie that carries `token` for the page's later requests.
std::string LiveTokenCookie(const std::string& token);

// For the options: a token is 16-128 characters of [A-Za-z0-9_-].
bool IsValidLiveToken(const std::string& token);

}  // namespace portcal
