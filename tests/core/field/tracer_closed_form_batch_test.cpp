// The four-lane closed form (ClosedFormBatch) against its slow twins,
// tracer::closed_form_field lane by lane and triangle_integrals: random
// triangles, points anywhere, in the plane inside and outside the triangle,
// just above and below it, next to an edge (in and off the plane) and next
// to a vertex; batches of 1 to 9 triangles, so full and partial passes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "field/tracer_closed_form.h"
#include "field/tracer_closed_form_batch.h"
#include "soupuv/field/triangle_integrals.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

constexpr int kModes = 7;
const char* const kModeNames[kModes] = {"anywhere",          "in plane inside", "above/below",
                                        "in plane past edge", "next to edge",   "next to edge off plane",
                                        "next to vertex"};

struct Case {
  Vec3 a, b, c, x;
  double d = 1;  // distance of x to the edge or vertex it is next to (modes 4-6)
};

// Next to an edge or vertex the field is ill-conditioned in any double
// evaluation: the distance d to the edge's line comes from O(1) coordinates
// with ~1e-16 absolute error, ~1e-16 / d relative, and enters the edge log:
// two evaluations rounding differently (FMA or not) may differ by that much,
// times a margin of 100 for the terms it multiplies. Elsewhere 1e-11: the
// scalar form itself differs from triangle_integrals by up to ~3e-12 above
// the triangle (tracer_closed_form_test.cpp); a wrong case or sign is O(1).
double allowed(const Case& k) { return 1e-11 + 1e-14 / k.d; }

Case random_case(std::mt19937& rng, int mode) {
  std::uniform_real_distribution<double> u(-1, 1), unit(0, 1), expo(-8, 0);
  Case k;
  k.a = {u(rng), u(rng), u(rng)};
  k.b = {u(rng), u(rng), u(rng)};
  k.c = {u(rng), u(rng), u(rng)};
  const Vec3 n = normalized(cross(k.b - k.a, k.c - k.a));
  double s = unit(rng), t = unit(rng);
  if (s + t > 1) s = 1 - s, t = 1 - t;
  const Vec3 inside = k.a + s * (k.b - k.a) + t * (k.c - k.a);
  const double h = std::pow(10.0, expo(rng));
  const double side = unit(rng) < 0.5 ? 1 : -1;
  const Vec3 out_ab = normalized(cross(k.b - k.a, n));  // in plane, away from c
  const Vec3 along = k.a + s * (k.b - k.a);
  switch (mode) {
    case 0: k.x = {2 * u(rng), 2 * u(rng), 2 * u(rng)}; break;
    case 1: k.x = inside; break;
    case 2: k.x = inside + side * h * n; break;
    case 3: k.x = along + (unit(rng) + 1e-3) * out_ab; break;
    case 4: k.x = along + side * h * out_ab; break;
    case 5: k.x = along + h * normalized(side * out_ab + u(rng) * n); break;
    default: k.x = k.a + h * normalized(Vec3{u(rng), u(rng), u(rng)}); break;
  }
  if (mode >= 4) k.d = h;
  return k;
}

}  // namespace

TEST(TracerClosedFormBatch, EachLaneMatchesClosedFormField) {
  std::mt19937 rng(5);
  double worst[kModes] = {};
  double worst_integrals = 0;
  for (int it = 0; it < 70000; ++it) {
    const int mode = it % kModes;
    const Case k = random_case(rng, mode);
    const tracer::TriangleFrame f = tracer::triangle_frame(k.a, k.b, k.c);
    const double density = 0.5 + (it % 3);
    tracer::ClosedFormBatch batch;
    double e[3] = {0, 0, 0};
    batch.add(f, density, k.x, e);
    batch.flush(e);
    const Vec3 got{e[0], e[1], e[2]};
    const Vec3 ref = density * tracer::closed_form_field(f, k.x);
    worst[mode] = std::max(worst[mode], norm(got - ref) / norm(ref) / allowed(k));
    const Vec3 slow = density * triangle_integrals(k.a, k.b, k.c, k.x).field;
    worst_integrals = std::max(worst_integrals, norm(got - slow) / norm(slow) / allowed(k));
  }
  // In units of allowed(): 1e-11 relative, more next to an edge or vertex.
  std::printf("batch lane vs closed_form_field, max rel difference / allowed:");
  for (int m = 0; m < kModes; ++m) std::printf(" %s %.1e%s", kModeNames[m], worst[m], m + 1 < kModes ? "," : "\n");
  std::printf("batch lane vs triangle_integrals, max rel difference / allowed: %.1e\n", worst_integrals);
  for (int m = 0; m < kModes; ++m) EXPECT_LT(worst[m], 1) << kModeNames[m];
  EXPECT_LT(worst_integrals, 10);
}

TEST(TracerClosedFormBatch, SumsOfPartialAndFullPasses) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  tracer::ClosedFormBatch batch;  // reused across points, as the tracer does
  for (int it = 0; it < 3000; ++it) {
    const int count = 1 + it % 9;
    const Case base = random_case(rng, it % kModes);
    double e[3] = {0, 0, 0};
    Vec3 ref{0, 0, 0};
    double scale = 0;
    // Triangles around the same point: the base one and random ones nearby
    // (the batch keeps pointers to the frames until the flush).
    std::vector<tracer::TriangleFrame> frames;
    for (int t = 0; t < count; ++t) {
      const Vec3 shift = t == 0 ? Vec3{0, 0, 0} : Vec3{u(rng), u(rng), u(rng)};
      frames.push_back(tracer::triangle_frame(base.a + shift, base.b + shift, base.c + shift));
    }
    for (int t = 0; t < count; ++t) {
      const tracer::TriangleFrame& f = frames[t];
      const double density = 1 + t;
      batch.add(f, density, base.x, e);
      const Vec3 g = density * tracer::closed_form_field(f, base.x);
      ref += g;
      scale += norm(g);
    }
    batch.flush(e);
    worst = std::max(worst, norm(Vec3{e[0], e[1], e[2]} - ref) / scale / allowed(base));
  }
  std::printf("batch sums of 1..9 triangles vs closed_form_field: max rel difference / allowed %.1e\n", worst);
  EXPECT_LT(worst, 1);
}

TEST(TracerClosedFormBatch, DegenerateTriangleAddsNothing) {
  tracer::ClosedFormBatch batch;
  double e[3] = {0, 0, 0};
  const tracer::TriangleFrame flat = tracer::triangle_frame({0, 0, 0}, {1, 0, 0}, {2, 0, 0});
  batch.add(flat, 1.0, {0.5, 0.5, 0.5}, e);
  batch.flush(e);
  EXPECT_EQ(e[0], 0.0);
  EXPECT_EQ(e[1], 0.0);
  EXPECT_EQ(e[2], 0.0);
}

// The potential, four at a time (the collocation's near matrix), against
// the scalar closed_form_potential and triangle_integrals' potential, in
// every mode above and in batches of 1 to 9 (full and partial passes).
// The potential is better conditioned than the field (its edge terms carry
// t0 * log, which vanishes at the edge), so the same allowance holds.
TEST(TracerClosedFormBatch, PotentialsMatchTheScalarFormsInEveryMode) {
  std::mt19937 rng(7);
  double worst[kModes] = {};
  double worst_integrals = 0;
  for (int it = 0; it < 21000; ++it) {
    const int count = 1 + it % 9;
    std::vector<Case> cases;
    std::vector<tracer::TriangleFrame> frames;
    const Case base = random_case(rng, it % kModes);
    for (int t = 0; t < count; ++t) {
      // Each triangle its own case, all seen from the base point's position
      // relative to it (so every lane is in the base case's mode).
      Case k = t == 0 ? base : random_case(rng, it % kModes);
      const Vec3 shift = base.x - k.x;
      k.a += shift, k.b += shift, k.c += shift, k.x = base.x;
      cases.push_back(k);
      frames.push_back(tracer::triangle_frame(k.a, k.b, k.c));
    }
    std::vector<const tracer::TriangleFrame*> pointers;
    for (const auto& f : frames) pointers.push_back(&f);
    std::vector<double> got(count);
    tracer::closed_form_potentials(pointers.data(), count, base.x, got.data());
    for (int t = 0; t < count; ++t) {
      const double ref = tracer::closed_form_potential(frames[t], base.x);
      const double slow = triangle_integrals(cases[t].a, cases[t].b, cases[t].c, base.x).potential;
      worst[it % kModes] = std::max(worst[it % kModes], std::fabs(got[t] - ref) / std::fabs(ref) / allowed(cases[t]));
      worst_integrals = std::max(worst_integrals, std::fabs(got[t] - slow) / std::fabs(slow) / allowed(cases[t]));
    }
  }
  std::printf("potential lanes vs closed_form_potential, max rel difference / allowed:");
  for (int m = 0; m < kModes; ++m) std::printf(" %s %.1e%s", kModeNames[m], worst[m], m + 1 < kModes ? "," : "\n");
  std::printf("potential lanes vs triangle_integrals, max rel difference / allowed: %.1e\n", worst_integrals);
  for (int m = 0; m < kModes; ++m) EXPECT_LT(worst[m], 1) << kModeNames[m];
  EXPECT_LT(worst_integrals, 1);
}
