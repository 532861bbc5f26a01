// Job-end callbacks (see callbacks.h).
#include "soupuv/server/callbacks.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <openssl/hmac.h>

#include <chrono>
#include <cstring>
#include <regex>

#include <httplib.h>

#include "soupuv/server/log.h"

namespace soupuv::server {
namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Url {
  std::string scheme, host, path;
  int port = 0;
};

std::optional<Url> parse_url(const std::string& url) {
  static const std::regex re(R"(^(https?)://(\[[0-9A-Fa-f:.]+\]|[A-Za-z0-9.-]+)(?::([0-9]{1,5}))?(/[^\s#]*)?$)");
  std::smatch m;
  if (!std::regex_match(url, m, re)) return std::nullopt;
  Url u;
  u.scheme = m[1];
  u.host = m[2];
  if (!u.host.empty() && u.host.front() == '[') u.host = u.host.substr(1, u.host.size() - 2);
  u.port = m[3].matched ? std::stoi(m[3]) : (u.scheme == "https" ? 443 : 80);
  u.path = m[4].matched ? std::string(m[4]) : "/";
  if (u.port < 1 || u.port > 65535) return std::nullopt;
  return u;
}

}  // namespace

std::string check_callback_url(const std::string& url) {
  if (url.size() > 2048) return "callback_url is longer than 2048 bytes";
  if (!parse_url(url)) return "callback_url must be an http:// or https:// URL with a host (no user info)";
  return "";
}

bool is_public_address(const std::string& address) {
  in_addr v4{};
  in6_addr v6{};
  auto v4_public = [](uint32_t a) {
    const uint8_t b0 = uint8_t(a >> 24), b1 = uint8_t(a >> 16);
    if (b0 == 0 || b0 == 10 || b0 == 127 || b0 >= 224) return false;  // this network, private, loopback, multicast+
    if (b0 == 169 && b1 == 254) return false;                          // link-local
    if (b0 == 172 && (b1 & 0xF0) == 16) return false;                  // private
    if (b0 == 192 && b1 == 168) return false;                          // private
    if (b0 == 100 && (b1 & 0xC0) == 64) return false;                  // CGNAT
    if (b0 == 192 && b1 == 0 && uint8_t(a >> 8) == 0) return false;     // IETF protocol assignments
    if (b0 == 198 && (b1 & 0xFE) == 18) return false;                  // benchmarking
    return true;
  };
  if (inet_pton(AF_INET, address.c_str(), &v4) == 1) return v4_public(ntohl(v4.s_addr));
  if (inet_pton(AF_INET6, address.c_str(), &v6) != 1) return false;
  const uint8_t* b = v6.s6_addr;
  static const uint8_t mapped[12] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF};
  if (std::memcmp(b, mapped, 12) == 0)
    return v4_public(uint32_t(b[12]) << 24 | uint32_t(b[13]) << 16 | uint32_t(b[14]) << 8 | b[15]);
  if (IN6_IS_ADDR_UNSPECIFIED(&v6) || IN6_IS_ADDR_LOOPBACK(&v6) || IN6_IS_ADDR_MULTICAST(&v6) ||
      IN6_IS_ADDR_LINKLOCAL(&v6) || IN6_IS_ADDR_SITELOCAL(&v6) || IN6_IS_ADDR_V4COMPAT(&v6))
    return false;
  if ((b[0] & 0xFE) == 0xFC) return false;  // unique local fc00::/7
  return true;
}

std::string hmac_sha256_hex(const std::string& key, const std::string& message) {
  unsigned char mac[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  HMAC(EVP_sha256(), key.data(), int(key.size()), reinterpret_cast<const unsigned char*>(message.data()),
       message.size(), mac, &len);
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < len; ++i) {
    out += hex[mac[i] >> 4];
    out += hex[mac[i] & 15];
  }
  return out;
}

CallbackSender::CallbackSender(std::string secret, bool allow_private, double first_delay_s)
    : secret_(std::move(secret)), allow_private_(allow_private), first_delay_s_(first_delay_s) {
  thread_ = std::thread([this] { loop(); });
}

CallbackSender::~CallbackSender() { stop(); }

void CallbackSender::stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void CallbackSender::post(const std::string& url, const nlohmann::json& body) {
  {
    std::lock_guard lock(mu_);
    queue_.push_back({url, body.dump(), 0, now_s()});
  }
  cv_.notify_all();
}

bool CallbackSender::attempt(const Delivery& d, std::string& error) {
  auto u = parse_url(d.url);
  if (!u) {
    error = "bad URL";
    return false;
  }
  // Resolve once; every address must be allowed; connect to the first.
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* res = nullptr;
  if (getaddrinfo(u->host.c_str(), nullptr, &hints, &res) != 0 || !res) {
    error = "host does not resolve";
    return false;
  }
  std::string first;
  bool refused = false;
  for (addrinfo* a = res; a; a = a->ai_next) {
    char buf[INET6_ADDRSTRLEN] = {};
    const void* src = a->ai_family == AF_INET ? static_cast<const void*>(&reinterpret_cast<sockaddr_in*>(a->ai_addr)->sin_addr)
                                              : static_cast<const void*>(&reinterpret_cast<sockaddr_in6*>(a->ai_addr)->sin6_addr);
    if (!inet_ntop(a->ai_family, src, buf, sizeof buf)) continue;
    if (!allow_private_ && !is_public_address(buf)) refused = true;
    if (first.empty()) first = buf;
  }
  freeaddrinfo(res);
  if (refused || first.empty()) {
    error = "refused: the host resolves to a loopback, private or reserved address (--callback-allow-private)";
    return false;
  }
  const std::string t = std::to_string(
      std::chrono::duration_cast<std::chrono::seconds>(std::chrono::system_clock::now().time_since_epoch()).count());
  httplib::Headers headers = {{"Soupuv-Signature", "t=" + t + ",v1=" + hmac_sha256_hex(secret_, t + "." + d.body)},
                              {"User-Agent", "soupuv-callback"}};
  auto send = [&](auto& client) {
    client.set_hostname_addr_map({{u->host, first}});
    client.set_connection_timeout(5);
    client.set_read_timeout(10);
    client.set_write_timeout(10);
    return client.Post(u->path.c_str(), headers, d.body, "application/json");
  };
  auto post = [&]() {
    if (u->scheme == "https") {
      httplib::SSLClient c(u->host, u->port);
      c.enable_server_certificate_verification(true);
      return send(c);
    }
    httplib::Client c(u->host, u->port);
    return send(c);
  };
  httplib::Result r = post();
  if (!r) {
    error = "no response (" + httplib::to_string(r.error()) + ")";
    return false;
  }
  if (r->status < 200 || r->status > 299) {
    error = "status " + std::to_string(r->status);
    return false;
  }
  return true;
}

void CallbackSender::loop() {
  std::unique_lock lock(mu_);
  for (;;) {
    if (stopping_) return;
    if (queue_.empty()) {
      cv_.wait(lock);
      continue;
    }
    // The delivery due first.
    auto next = std::min_element(queue_.begin(), queue_.end(), [](auto& a, auto& b) { return a.due < b.due; });
    const double wait = next->due - now_s();
    if (wait > 0) {
      cv_.wait_for(lock, std::chrono::duration<double>(wait));
      continue;
    }
    Delivery d = *next;
    queue_.erase(next);
    lock.unlock();
    std::string error;
    const bool ok = attempt(d, error);
    lock.lock();
    if (ok) {
      log::info("callback delivered", {{"attempt", d.attempt + 1}});
      continue;
    }
    if (++d.attempt < kAttempts) {
      d.due = now_s() + first_delay_s_ * double(1 << (d.attempt - 1));
      log::warn("callback failed, retrying", {{"attempt", d.attempt}, {"error", error}});
      queue_.push_back(d);
    } else {
      log::warn("callback given up", {{"attempts", d.attempt}, {"error", error}});
    }
  }
}

}  // namespace soupuv::server
