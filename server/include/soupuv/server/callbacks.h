// Job-end callbacks: a caller may give a job a `callback_url` (kept in the
// job's params, so every job store persists it); when the job ends, the server
// POSTs the job's JSON there, signed, and retries with backoff.
//
// Signature: header `Soupuv-Signature: t=<unix seconds>,v1=<hex>` where hex is
// HMAC-SHA256(secret, "<t>.<body>") — the receiver recomputes it with the
// shared secret (--callback-secret / SOUPUV_CALLBACK_SECRET) and rejects old t.
// SSRF guard: the URL's host is resolved once per attempt and every address
// must be public (not loopback, private, link-local, CGNAT, unspecified,
// multicast or reserved) unless --callback-allow-private; the request then
// goes to that resolved address (no second lookup a rebinding DNS could change).
// Delivery: up to kAttempts POSTs, 1 s, 2 s, 4 s, ... apart; any 2xx ends it.
#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

namespace soupuv::server {

// "" when `url` is an acceptable callback URL (http or https, a host, at most
// 2048 bytes, no user info); otherwise why not.
std::string check_callback_url(const std::string& url);

// True when `address` (numeric IPv4/IPv6) is a public unicast address.
bool is_public_address(const std::string& address);

// hex(HMAC-SHA256(key, message)).
std::string hmac_sha256_hex(const std::string& key, const std::string& message);

class CallbackSender {
 public:
  static constexpr int kAttempts = 5;
  CallbackSender(std::string secret, bool allow_private, double first_delay_s = 1.0);
  ~CallbackSender();
  void post(const std::string& url, const nlohmann::json& body);  // queued; returns at once
  void stop();

 private:
  struct Delivery {
    std::string url, body;
    int attempt = 0;
    double due = 0;
  };
  void loop();
  bool attempt(const Delivery& d, std::string& error);

  std::string secret_;
  bool allow_private_;
  double first_delay_s_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Delivery> queue_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace soupuv::server
