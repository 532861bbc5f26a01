// The parallel driver both grid extractors share (marching cubes, marching
// tetrahedra): every leaf cell of the narrow band meshed by a per-thread
// mesher, the per-thread lists welded into one mesh.
//
//   mesh_band_cells(band, stage, progress, make_mesher)
//     make_mesher(vertices, triangles) -> a callable mesher(n) that appends
//       cell n's surface (edge vertices by key, key-triangles) to the thread's
//       two lists; called once per thread.
//   -> weld_edge_vertices of the lists (edge_vertex_weld.h).
// Static contiguous chunks: thread t gets the t-th run of cells, so the
// per-thread lists concatenated in thread order are in cell order — the same
// mesh for every thread count (the edge collapse depends on face order). The
// first exception of any cell is rethrown after the loop (first_error.h).
#pragma once

#include <omp.h>

#include <array>
#include <cstdint>
#include <vector>

#include "edge_vertex_weld.h"
#include "first_error.h"
#include "soupuv/progress.h"
#include "soupuv/proxy/narrow_band.h"

namespace soupuv::proxy {

template <class MakeMesher>
TriMesh mesh_band_cells(const NarrowBand& band, const char* stage, Progress& progress,
                        MakeMesher&& make_mesher) {
  int threads = omp_get_max_threads();
  std::vector<std::vector<EdgeVertex>> vertices(threads);
  std::vector<std::vector<std::array<uint64_t, 3>>> triangles(threads);
  long n_cells = long(band.cells.size());
  FirstError errors;
#pragma omp parallel
  {
    int me = omp_get_thread_num();
    auto mesher = make_mesher(vertices[me], triangles[me]);
#pragma omp for schedule(static)
    for (long n = 0; n < n_cells; ++n)
      errors.run([&] {
        if (me == 0 && n % 4096 == 0) progress.update(stage, double(n) / n_cells);
        mesher(size_t(n));
      });
  }
  errors.rethrow();
  return weld_edge_vertices(vertices, triangles);
}

}  // namespace soupuv::proxy
