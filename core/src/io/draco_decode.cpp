#include "io/draco_decode.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include "io/checked_json.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

bool has_draco_magic(std::span<const uint8_t> bytes) {
  return bytes.size() >= 5 && std::memcmp(bytes.data(), "DRACO", 5) == 0;
}

namespace {

// Decodes in this process. Draco 1.5.5 has loops bounded only by counts read
// from the stream (a 574-byte fuzzed payload spins for 13-45 s), so
// decode_draco runs this in a child process under a CPU-time limit.
DracoMesh decode_in_process(std::span<const uint8_t> bytes, int64_t position_attribute_id,
                            uint64_t max_triangles, const std::string& where) {
  if (!has_draco_magic(bytes)) fail_input(where + ": Draco payload does not start with 'DRACO'");
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  auto type = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!type.ok()) fail_input(where + ": Draco header unreadable: " + type.status().error_msg_string());
  if (type.value() == draco::POINT_CLOUD)
    throw Error(ErrorCode::no_triangles, where + ": Draco point cloud has no triangles to map");
  if (type.value() != draco::TRIANGULAR_MESH) fail_input(where + ": Draco payload is not a triangle mesh");

  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) fail_input(where + ": Draco decoding failed: " + decoded.status().error_msg_string());
  const draco::Mesh& mesh = *decoded.value();

  if (mesh.num_faces() > max_triangles)
    throw Error(ErrorCode::limit_exceeded, where + ": Draco mesh has " + std::to_string(mesh.num_faces()) +
                                               " faces, over the triangle limit");
  const draco::PointAttribute* pos =
      position_attribute_id >= 0
          ? mesh.GetAttributeByUniqueId(uint32_t(position_attribute_id))
          : mesh.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (!pos) fail_input(where + ": Draco mesh has no POSITION attribute" +
                       (position_attribute_id >= 0 ? " with id " + std::to_string(position_attribute_id) : ""));
  if (pos->num_components() < 3) fail_input(where + ": Draco POSITION has fewer than 3 components");

  // Draco points map to attribute values through an optional index map;
  // check both levels before reading anything.
  const uint32_t points = mesh.num_points();
  if (!pos->is_mapping_identity() && pos->indices_map_size() < points)
    fail_input(where + ": Draco POSITION map shorter than the point count");
  DracoMesh out;
  out.positions.resize(points);
  for (uint32_t p = 0; p < points; ++p) {
    draco::AttributeValueIndex v = pos->mapped_index(draco::PointIndex(p));
    if (v.value() >= pos->size()) fail_input(where + ": Draco POSITION value index out of range");
    float xyz[3];
    if (!pos->ConvertValue<float>(v, 3, xyz)) fail_input(where + ": Draco POSITION values unreadable");
    out.positions[p] = {xyz[0], xyz[1], xyz[2]};
  }
  out.triangles.resize(mesh.num_faces());
  for (uint32_t f = 0; f < mesh.num_faces(); ++f) {
    const auto& face = mesh.face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      uint32_t i = face[k].value();
      if (i >= points)
        fail_input(where + ": Draco face " + std::to_string(f) + " index " + std::to_string(i) +
                   " >= point count " + std::to_string(points));
      out.triangles[f][k] = i;
    }
  }
  return out;
}

// The child's answer on the pipe: a status byte (0 = mesh follows, else
// ErrorCode + 1 and a message), then counts and raw arrays.
bool write_all(int fd, const void* data, size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= size_t(w);
  }
  return true;
}

[[noreturn]] void child_decode(int fd, std::span<const uint8_t> bytes, int64_t position_attribute_id,
                               uint64_t max_triangles, const std::string& where, unsigned cpu_seconds) {
  rlimit cpu{cpu_seconds, cpu_seconds + 1};
  setrlimit(RLIMIT_CPU, &cpu);
  uint8_t status = 0;
  std::string message;
  DracoMesh mesh;
  try {
    mesh = decode_in_process(bytes, position_attribute_id, max_triangles, where);
  } catch (const Error& e) {
    status = uint8_t(int(e.code()) + 1);
    message = e.what();
  } catch (const std::exception& e) {
    status = uint8_t(int(ErrorCode::invalid_input) + 1);
    message = where + ": Draco decoding failed: " + e.what();
  }
  bool ok = write_all(fd, &status, 1);
  if (status != 0) {
    uint64_t n = message.size();
    ok = ok && write_all(fd, &n, 8) && write_all(fd, message.data(), n);
  } else {
    uint64_t counts[2] = {mesh.positions.size(), mesh.triangles.size()};
    ok = ok && write_all(fd, counts, 16) && write_all(fd, mesh.positions.data(), counts[0] * sizeof(Vec3)) &&
         write_all(fd, mesh.triangles.data(), counts[1] * sizeof(Tri));
  }
  _exit(ok ? 0 : 1);  // no atexit handlers or destructors: this is a fork
}

// Reads exactly n bytes from the child's output at `at`, or fails.
void take(const std::vector<uint8_t>& in, size_t& at, void* out, uint64_t n, const std::string& where) {
  if (n > in.size() - at) fail_input(where + ": Draco decoder process returned a short answer");
  std::memcpy(out, in.data() + at, size_t(n));
  at += size_t(n);
}

}  // namespace

DracoMesh decode_draco(std::span<const uint8_t> bytes, int64_t position_attribute_id,
                       uint64_t max_triangles, const std::string& where) {
  if (!has_draco_magic(bytes)) fail_input(where + ": Draco payload does not start with 'DRACO'");
  // Honest payloads decode at well over 100 kB per CPU second; the budget
  // grows with the payload so only hostile streams hit it.
  const unsigned cpu_seconds = unsigned(std::min<uint64_t>(3600, 2 + bytes.size() / 50'000));
  int fds[2];
  if (pipe(fds) != 0) throw Error(ErrorCode::internal, where + ": cannot create a pipe for Draco decoding");
  pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    throw Error(ErrorCode::internal, where + ": cannot fork the Draco decoder");
  }
  if (pid == 0) {
    close(fds[0]);
    child_decode(fds[1], bytes, position_attribute_id, max_triangles, where, cpu_seconds);
  }
  close(fds[1]);
  std::vector<uint8_t> answer;
  uint8_t chunk[1 << 16];
  for (;;) {
    ssize_t r = ::read(fds[0], chunk, sizeof chunk);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    answer.insert(answer.end(), chunk, chunk + r);
  }
  close(fds[0]);
  int wstatus = 0;
  while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(wstatus) && (WTERMSIG(wstatus) == SIGXCPU || WTERMSIG(wstatus) == SIGKILL))
    throw Error(ErrorCode::limit_exceeded, where + ": Draco decoding exceeded its CPU budget of " +
                                               std::to_string(cpu_seconds) + " s (hostile or corrupt payload)");
  if (!WIFEXITED(wstatus) || WEXITSTATUS(wstatus) != 0 || answer.empty())
    fail_input(where + ": Draco decoder process failed on this payload");

  size_t at = 0;
  uint8_t status = 0;
  take(answer, at, &status, 1, where);
  if (status != 0) {
    uint64_t n = 0;
    take(answer, at, &n, 8, where);
    std::string message(size_t(std::min<uint64_t>(n, answer.size())), '\0');
    take(answer, at, message.data(), n, where);
    int code = status - 1;
    if (code < 0 || code > int(ErrorCode::internal)) fail_input(where + ": bad answer from the Draco decoder process");
    throw Error(ErrorCode(code), message);
  }
  uint64_t counts[2];
  take(answer, at, counts, 16, where);
  if (counts[1] > max_triangles || counts[0] > answer.size() / sizeof(Vec3))
    fail_input(where + ": Draco decoder process returned inconsistent counts");
  DracoMesh mesh;
  mesh.positions.resize(size_t(counts[0]));
  mesh.triangles.resize(size_t(counts[1]));
  take(answer, at, mesh.positions.data(), counts[0] * sizeof(Vec3), where);
  take(answer, at, mesh.triangles.data(), counts[1] * sizeof(Tri), where);
  // Trust nothing from the other side of the pipe either.
  for (const Tri& t : mesh.triangles)
    for (uint32_t v : t)
      if (v >= mesh.positions.size()) fail_input(where + ": Draco face index out of range");
  return mesh;
}

}  // namespace soupuv::io::detail
