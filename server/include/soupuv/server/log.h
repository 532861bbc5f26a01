// JSON logs: one object per line on stderr, {"ts","level","msg",...fields}.
// spdlog 1.10 has no JSON formatter, so the pattern supplies ts and level and
// the message is the rest of an object dumped by nlohmann (invalid UTF-8
// replaced, so a hostile file name cannot break the line format).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace soupuv::server::log {

void init(const std::string& level);
void info(const std::string& msg, const nlohmann::json& fields = nlohmann::json::object());
void warn(const std::string& msg, const nlohmann::json& fields = nlohmann::json::object());
void error(const std::string& msg, const nlohmann::json& fields = nlohmann::json::object());
void debug(const std::string& msg, const nlohmann::json& fields = nlohmann::json::object());

// The "msg" plus fields as JSON members without the enclosing braces.
std::string members(const std::string& msg, const nlohmann::json& fields);

}  // namespace soupuv::server::log
