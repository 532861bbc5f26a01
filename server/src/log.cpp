#include "soupuv/server/log.h"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

namespace soupuv::server::log {
namespace {

std::shared_ptr<spdlog::logger>& logger() {
  static std::shared_ptr<spdlog::logger> l = [] {
    auto lg = spdlog::stderr_logger_mt("soupuv-server");
    lg->set_pattern(R"({"ts":"%Y-%m-%dT%H:%M:%S.%fZ","level":"%l",%v})", spdlog::pattern_time_type::utc);
    lg->flush_on(spdlog::level::info);
    return lg;
  }();
  return l;
}

void emit(spdlog::level::level_enum lvl, const std::string& msg, const nlohmann::json& fields) {
  auto& l = logger();
  if (!l->should_log(lvl)) return;
  l->log(lvl, "{}", members(msg, fields));
}

}  // namespace

std::string members(const std::string& msg, const nlohmann::json& fields) {
  nlohmann::json obj = nlohmann::json::object();
  obj["msg"] = msg;
  if (fields.is_object())
    for (auto it = fields.begin(); it != fields.end(); ++it) obj[it.key()] = it.value();
  std::string s = obj.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return s.substr(1, s.size() - 2);  // drop { } — the pattern supplies them
}

void init(const std::string& level) { logger()->set_level(spdlog::level::from_str(level)); }
void info(const std::string& m, const nlohmann::json& f) { emit(spdlog::level::info, m, f); }
void warn(const std::string& m, const nlohmann::json& f) { emit(spdlog::level::warn, m, f); }
void error(const std::string& m, const nlohmann::json& f) { emit(spdlog::level::err, m, f); }
void debug(const std::string& m, const nlohmann::json& f) { emit(spdlog::level::debug, m, f); }

}  // namespace soupuv::server::log
