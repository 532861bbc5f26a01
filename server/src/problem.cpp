#include "soupuv/server/problem.h"

#include "soupuv/server/log.h"

namespace soupuv::server {

const char* status_title(int status) {
  switch (status) {
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 409: return "Conflict";
    case 411: return "Length Required";
    case 413: return "Content Too Large";
    case 414: return "URI Too Long";
    case 415: return "Unsupported Media Type";
    case 422: return "Unprocessable Content";
    case 429: return "Too Many Requests";
    case 500: return "Internal Server Error";
    case 501: return "Not Implemented";
    case 503: return "Service Unavailable";
    case 504: return "Gateway Timeout";
    default: return "Error";
  }
}

const std::vector<ProblemType>& problem_types() {
  static const std::vector<ProblemType> types = {
      {"bad-request", "Bad request", "The request line or headers could not be parsed."},
      {"bad-idempotency-key", "Bad Idempotency-Key", "Idempotency-Key must be 1-128 characters of [A-Za-z0-9-_.:]."},
      {"idempotency-key-reused", "Idempotency-Key reused",
       "This Idempotency-Key was already used by this tenant with a different request; use a new key."},
      {"incomplete-body", "Incomplete body", "The request body ended before Content-Length bytes; send it again."},
      {"insufficient-storage", "Insufficient storage",
       "The server is low on disk space and refuses uploads for now; retry after Retry-After seconds."},
      {"internal", "Internal error", "The server failed; the error is logged. Retrying may help."},
      {"invalid-form", "Invalid form", "The multipart body needs one 'file' part (.glb, .gltf, .drc or a .zip of the "
                                       "folder) and may have 'files' (the files a .gltf names), 'params' (JSON) and "
                                       "'texture' (PNG or JPEG) parts."},
      {"invalid-params", "Invalid parameters", "A parameter is unknown, of the wrong type or out of range; see GET /v1/params."},
      {"invalid-zip", "Invalid zip", "The zip of a model's folder is unreadable, holds no model or several, or an entry "
                                     "is refused (a path leaving the folder, a symbolic link, too many entries)."},
      {"metadata-too-large", "Metadata too large", "A job's metadata object may take at most 4096 bytes as compact JSON."},
      {"invalid-query", "Invalid query", "A query parameter of the list is invalid (state, limit, cursor)."},
      {"invalid-token", "Invalid token", "The bearer token is not accepted (unknown or revoked)."},
      {"unauthorized", "Unauthorized", "This server needs Authorization: Bearer <token>."},
      {"invalid-model", "Invalid model", "The uploaded file is not a model the loader accepts; detail has its reason."},
      {"no-triangles", "No triangles", "The model has no triangles to map."},
      {"external-uri", "External URI", "glTF buffers and images must be embedded (data: URIs or GLB); external files are refused."},
      {"not-found", "Not found", "No such resource, or a job of another tenant."},
      {"not-finished", "Job not finished", "The job has no results (yet); its state is in the answer."},
      {"job-not-finished", "Job not finished", "Only a finished job can be deleted; cancel it first with POST /v1/jobs/{id}:cancel."},
      {"job-finished", "Job finished", "The job finished before it could be canceled; nothing was changed."},
      {"queue-full", "Queue full", "Too many jobs are waiting; retry after Retry-After seconds."},
      {"unavailable", "Unavailable", "The server is not accepting this now (no worker, stopping); retry later."},
      {"uploads-busy", "Uploads busy", "Too many uploads are in progress; retry after Retry-After seconds."},
      {"storage-unavailable", "Storage unavailable",
       "The server cannot store data right now (full disk, job store failing); retry after Retry-After seconds."},
      {"too-large", "Too large", "The body or a part of it exceeds the server's limit (GET /v1/params: max_upload_bytes)."},
      {"uri-too-long", "URI too long", "The request path is too long."},
      {"length-required", "Length required", "Send Content-Length (one, decimal); Transfer-Encoding is not accepted."},
      {"unsupported-encoding", "Unsupported encoding", "Content-Encoding is not accepted; send the file as is."},
      {"unsupported-media-type", "Unsupported media type",
       "Content-Type must be model/gltf-binary, model/gltf+json, application/octet-stream (Draco) or multipart/form-data."},
      {"request-timeout", "Request timeout", "The request head did not arrive within the server's header timeout."},
      {"header-too-large", "Header too large", "The request head has more bytes or lines than the server accepts."},
      {"method-not-allowed", "Method not allowed", "The resource does not take this method or a body; see the Allow header."},
  };
  return types;
}

const ProblemType* find_problem_type(const std::string& slug) {
  for (const auto& t : problem_types())
    if (slug == t.slug) return &t;
  return nullptr;
}

void set_problem(httplib::Response& res, int status, const std::string& slug, const std::string& detail,
                 const nlohmann::json& extra) {
  std::string type = "/problems/" + slug;
  if (!find_problem_type(slug)) {  // a slug missing from the table: a bug, never a broken link
    log::error("problem type missing from problem_types()", {{"slug", slug}});
    type = "about:blank";
  }
  nlohmann::json p = {{"type", type}, {"title", status_title(status)}, {"status", status}, {"detail", detail}};
  if (extra.is_object())
    for (auto it = extra.begin(); it != extra.end(); ++it) p[it.key()] = it.value();
  res.status = status;
  res.set_content(p.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                  "application/problem+json");
}

}  // namespace soupuv::server
