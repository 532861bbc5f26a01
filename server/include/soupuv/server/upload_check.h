// Cheap container checks of an uploaded model, done by the server before a job
// is queued (the loader in the worker does the full defensive parse):
//  - GLB: magic, version 2, declared length == bytes received, a JSON first
//    chunk inside the file, that JSON parses;
//  - glTF JSON: parses;
//  - both: every buffer/image `uri` must be a data: URI, or, for a folder
//    upload (`folder`), a plain relative path (no scheme, no absolute path,
//    no '..'): the worker then reads it from the upload's own folder; the
//    server itself never reads files named by an upload;
//  - Draco: the "DRACO" magic.
// Input: the file on disk and its declared kind. Output: ok, or a 400 reason.
#pragma once

#include <filesystem>
#include <string>

namespace soupuv::server {

enum class ModelKind { glb, gltf, draco };

struct UploadVerdict {
  bool ok = true;
  std::string slug;    // problem type when !ok
  std::string detail;  // one line
};

UploadVerdict check_model_file(const std::filesystem::path& file, ModelKind kind, bool folder = false);
const char* file_name_for(ModelKind kind);  // input.glb / input.gltf / input.drc

}  // namespace soupuv::server
