// Topology checks of a triangle mesh, measured rather than assumed.
//
// Input:  a TriMesh.
// Output: closed (every edge has two faces), oriented (each directed edge once,
//         its twin present), manifold (closed, oriented, and the faces around
//         every used vertex form one fan), degenerate (zero-area) face count,
//         V, E, F and the Euler characteristic V - E + F.
#pragma once

#include <cstddef>

#include "soupuv/mesh.h"

namespace soupuv::proxy {

struct Topology {
  bool closed = false;
  bool oriented = false;
  bool manifold = false;
  size_t degenerate_faces = 0;
  long vertices = 0, edges = 0, faces = 0;  // used vertices only
  long euler() const { return vertices - edges + faces; }
};

Topology check_topology(const TriMesh& mesh);

}  // namespace soupuv::proxy
