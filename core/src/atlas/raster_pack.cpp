#include "atlas/raster_pack.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <numeric>

#include <omp.h>

#include "atlas/chart_raster.h"
#include "atlas/pack.h"
#include "atlas/turn_chart.h"

namespace soupuv::atlas {
namespace {

// Packings a search may spend beyond its budget while nothing has fit
// (each 3 % smaller: 0.97^40 is a third of the starting scale).
constexpr int kPackingsWithoutFit = 40;

// Charts from which one chart's turns are searched in parallel.
constexpr int kParallelTurnsMin = 64;

// Charts of at least this share of the total area are placed by the pilot
// rule (RasterPackOptions::pilot_charts), each looking this many large
// charts ahead.
constexpr double kPilotShare = 0.01;
constexpr int kPilotLookahead = 3;

// Occupancy of a strip of texels, per row as signed run lengths: run > 0
// means that many free texels from here rightward, run < 0 that many
// occupied. widest(y) is the longest free run of row y, so rows that cannot
// take a chart's row are skipped with one comparison.
class RowRuns {
 public:
  RowRuns(int width, int height)
      : width_(width), height_(height), dirty_(height), run_(static_cast<size_t>(width) * height), widest_(height) {}
  int width() const { return width_; }
  int height() const { return height_; }
  // All free again (only the rows filled since the last reset are touched).
  void reset() {
    for (int y = 0; y < dirty_; ++y) {
      int16_t* row = &run_[static_cast<size_t>(y) * width_];
      for (int x = 0; x < width_; ++x) row[x] = static_cast<int16_t>(width_ - x);
      widest_[y] = width_;
    }
    dirty_ = 0;
  }
  // The same occupancy as `other` (same size), copying only rows either
  // has filled.
  void assign(const RowRuns& other) {
    const int rows = std::max(dirty_, other.dirty_);
    std::copy(other.run_.begin(), other.run_.begin() + static_cast<size_t>(rows) * width_, run_.begin());
    std::copy(other.widest_.begin(), other.widest_.begin() + rows, widest_.begin());
    dirty_ = other.dirty_;
  }
  int run(int x, int y) const { return run_[static_cast<size_t>(y) * width_ + x]; }
  int widest(int y) const { return widest_[y]; }
  // Marks texels a..b of row y occupied (clipped to the strip).
  void fill(int y, int a, int b) {
    if (y < 0 || y >= height_) return;
    a = std::max(a, 0);
    b = std::min(b, width_ - 1);
    if (a > b) return;
    dirty_ = std::max(dirty_, y + 1);
    int16_t* row = &run_[static_cast<size_t>(y) * width_];
    for (int x = b; x >= a; --x) row[x] = static_cast<int16_t>(x + 1 < width_ && row[x + 1] < 0 ? row[x + 1] - 1 : -1);
    // Leftward, each run depends only on its right neighbour: stop at the
    // first one that does not change.
    for (int x = a - 1; x >= 0; --x) {
      const bool occupied = row[x] < 0;
      const int right = row[x + 1];
      const int16_t now = static_cast<int16_t>(occupied ? (right < 0 ? right - 1 : -1) : (right < 0 ? 1 : right + 1));
      if (now == row[x]) break;
      row[x] = now;
    }
    int widest = 0;
    for (int x = 0; x < width_; x += std::abs(row[x])) widest = std::max(widest, static_cast<int>(row[x]));
    widest_[y] = widest;
  }

 private:
  int width_, height_;
  int dirty_;  // rows below this may have been filled since the last reset
  std::vector<int16_t> run_;
  std::vector<int> widest_;
};

// A chart turned by one of the trial angles: every vertex turned (unscaled),
// and the turned bounding box (turn_chart.h).
using Turn = TurnedChart;

// Texel position of a turned vertex in the chart's own frame; the raster and
// the final UVs both come from here, so the written chart lies exactly on the
// texels tested.
Vec2 local_texel(const Turn& t, int vertex, double scale) {
  return (t.uv[vertex] - t.lo) * scale;
}

// Longest interval of each mask row: the quick test against widest().
std::vector<int> row_needs(const RowMask& m) {
  std::vector<int> need(m.height, 0);
  for (int r = 0; r < m.height; ++r)
    for (int s = m.first[r]; s < m.first[r + 1]; ++s) need[r] = std::max(need[r], m.spans[s].b - m.spans[s].a + 1);
  return need;
}

struct Spot {
  int x = -1, y = -1;
};

// Lowest row, then leftmost column, where the mask fits with its bottom row
// at y <= y_limit; x = -1 if none.
Spot first_fit(const RowRuns& occ, const RowMask& m, const std::vector<int>& need, int y_limit) {
  const int h = m.height, w = m.width;
  if (h == 0 || w > occ.width()) return {};
  y_limit = std::min(y_limit, occ.height() - h);
  const int min_need = *std::min_element(need.begin(), need.end());
  int hint = 0;  // the mask row that blocked last: usually blocks again
  for (int y = 0; y <= y_limit; ++y) {
    bool wide_enough = true;
    for (int i = 0, r = hint; i < h; ++i, r = r + 1 < h ? r + 1 : 0) {
      if (occ.widest(y + r) < need[r]) {
        wide_enough = false;
        if (occ.widest(y + r) < min_need) {
          // No mask row fits texel row y + r: every y up to y + r would put
          // one there.
          y += r;
          hint = h - 1;
        } else {
          // At y + 1 the same texel row meets mask row r - 1.
          hint = r > 0 ? r - 1 : 0;
        }
        break;
      }
    }
    if (!wide_enough) continue;
    int x = 0;
    while (x + w <= occ.width()) {
      int next = x;
      for (int i = 0, r = hint; i < h && next == x; ++i, r = r + 1 < h ? r + 1 : 0) {
        for (int s = m.first[r]; s < m.first[r + 1]; ++s) {
          const int a = x + m.spans[s].a, len = m.spans[s].b - m.spans[s].a + 1;
          const int v = occ.run(a, y + r);
          if (v >= len) continue;
          // Every column before `next` would still cover the blocking texels.
          if (v <= 0) next = x - v;
          else next = a + v < occ.width() ? x + v - occ.run(a + v, y + r) : occ.width();
          hint = r;
          break;
        }
      }
      if (next == x) return {x, y};
      x = next;
    }
  }
  return {};
}

struct Placed {
  int turn = 0;
  Spot at;
};

// Marks mask m placed at `at` occupied, grown by the padding: a later
// chart's own texels that miss these keep the padding from this one.
// `grown`: the mask dilated by pad.
void occupy_grown(RowRuns& occ, const RowMask& grown, Spot at, int pad) {
  for (int r = 0; r < grown.height; ++r)
    for (int j = grown.first[r]; j < grown.first[r + 1]; ++j)
      occ.fill(at.y - pad + r, at.x - pad + grown.spans[j].a, at.x - pad + grown.spans[j].b);
}

void occupy(RowRuns& occ, const RowMask& m, Spot at, int pad) { occupy_grown(occ, dilate(m, pad), at, pad); }

}  // namespace

RasterPackResult raster_pack(std::vector<PackChart>& charts, int texture_size, double padding_px,
                             double scale_to_beat, const RasterPackOptions& options) {
  RasterPackResult result;
  const int n = static_cast<int>(charts.size());
  if (n == 0 || texture_size > 4096 || options.angles < 1) return result;
  const int pad = static_cast<int>(std::ceil(padding_px - 1e-9));
  // Charts keep half the padding from the texture's border (the texture may
  // repeat). The strip is twice as tall as the square to measure overflow.
  const int margin = (pad + 1) / 2;
  const int side = texture_size - 2 * margin;
  if (side < 1) return result;
  RowRuns occ(side, 2 * side);

  std::vector<std::vector<Turn>> turns(n);
  // The turns of the charts whose shape depends on the scale, at `scale`.
  auto reshape = [&](double scale) {
    if (!options.at_scale || !options.elastic) return;
    options.at_scale(scale);
    for (int i = 0; i < n; ++i)
      if ((*options.elastic)[i])
        for (int k = 0; k < options.angles; ++k) turns[i][k] = turn_chart(*charts[i].uv, 2 * M_PI * k / options.angles);
  };
  std::vector<double> area(n, 0);
  double total_area = 0;
  for (int i = 0; i < n; ++i) {
    const auto& uv = *charts[i].uv;
    for (const auto& t : *charts[i].triangles) area[i] += 0.5 * std::fabs(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]));
    total_area += area[i];
  }
  if (!(total_area > 0)) return result;
  // Small charts try a few quarter turns from the pose with their
  // minimal-area rectangle's axis along x (RasterPackOptions::
  // small_chart_share): their first turn is that pose.
  const int quarter = options.angles / 4;
  std::vector<uint8_t> small(n, 0);
  std::vector<double> pose(n, 0);
  for (int i = 0; i < n; ++i) {
    small[i] = options.small_chart_angles > 0 && options.angles % 4 == 0 &&
               area[i] < options.small_chart_share * total_area && !(options.elastic && (*options.elastic)[i]);
    if (!small[i]) continue;
    const Vec2 axis = min_area_rectangle(*charts[i].uv).axis;
    pose[i] = -std::atan2(axis.y, axis.x);
  }
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < options.angles; ++k)
      turns[i].push_back(turn_chart(*charts[i].uv, pose[i] + 2 * M_PI * k / options.angles));
  // Two orders: largest area first and longest side first.
  std::vector<int> by_area(n);
  std::iota(by_area.begin(), by_area.end(), 0);
  std::vector<int> by_side = by_area;
  std::stable_sort(by_area.begin(), by_area.end(), [&](int a, int b) { return area[a] > area[b]; });
  std::vector<double> side_length(n, 0);
  for (int i = 0; i < n; ++i)
    for (const Vec2& p : turns[i][0].uv)
      side_length[i] = std::max({side_length[i], p.x - turns[i][0].lo.x, p.y - turns[i][0].lo.y});
  std::stable_sort(by_side.begin(), by_side.end(), [&](int a, int b) { return side_length[a] > side_length[b]; });

  // One packing at `scale`: the strip rows used, or INT_MAX if a chart found
  // no place in the strip.
  std::vector<RowMask> masks(static_cast<size_t>(n) * options.angles);
  // Turns not rasterised: too big for the strip, or not tried (small charts).
  std::vector<uint8_t> too_big(masks.size(), 0);
  std::vector<Placed> placed(n), best;
  // The greedy's place for chart i on `strip`: the least score y + w *
  // height over its turns, ties to the lower turn (the main loop's rule).
  auto greedy_place = [&](const RowRuns& strip, int i, double height_weight) {
    Placed p{-1, {}};
    double best_score = INFINITY;
    for (int k = 0; k < options.angles; ++k) {
      if (too_big[static_cast<size_t>(i) * options.angles + k]) continue;
      const RowMask& m = masks[static_cast<size_t>(i) * options.angles + k];
      const double slack = best_score - height_weight * m.height;
      const int y_limit = std::isinf(best_score) ? strip.height() : static_cast<int>(std::ceil(slack)) - 1;
      if (y_limit < 0) continue;
      const Spot s = first_fit(strip, m, row_needs(m), y_limit);
      if (s.x < 0) continue;
      best_score = s.y + height_weight * m.height;
      p = {k, s};
    }
    return p;
  };
  // The pilot rule for the largest charts (those of at least kPilotShare of
  // the area, at most options.pilot_charts, in the packing's order): the
  // rows a packing uses are mostly set by where its few largest charts
  // stack, which the greedy decides one chart at a time. Each of those
  // charts instead takes, among its turns at their first-fit places, the
  // one after which the greedy places the next kPilotLookahead large
  // charts lowest (the rows they use; ties to the greedy's own pick). The
  // picks go to `placed`; returns how many charts were placed so.
  // The turns of a chart are tried on the threads at once, each on its own
  // copy of the strip (the pilot was most of a many-island packing's time,
  // on one thread: table 0.91 of 1.1 s); the pick is made after, in turn
  // order, by the same rule, so the packing does not depend on the threads.
  const int pilot_team = std::max(1, std::min(options.threads, options.angles));
  RowRuns prefix_occ(options.pilot_charts > 0 ? side : 0, options.pilot_charts > 0 ? 2 * side : 0);
  std::vector<RowRuns> trial_occ(options.pilot_charts > 0 ? pilot_team : 0, prefix_occ);
  auto pilot = [&](const std::vector<int>& order, double height_weight) {
    int count = 0;
    while (count < std::min<int>(options.pilot_charts, int(order.size())) &&
           area[order[count]] >= kPilotShare * total_area)
      ++count;
    if (count < 2) return 0;
    const int angles = options.angles;
    auto mask_of = [&](int i, int turn) -> const RowMask& {
      return masks[static_cast<size_t>(i) * angles + turn];
    };
    // The large charts' masks grown by the padding, every turn that can fit.
    std::vector<RowMask> grown(static_cast<size_t>(count) * angles);
#pragma omp parallel for schedule(dynamic, 1) num_threads(pilot_team)
    for (int g = 0; g < count * angles; ++g)
      if (!too_big[static_cast<size_t>(order[g / angles]) * angles + g % angles])
        grown[g] = dilate(mask_of(order[g / angles], g % angles), pad);
    auto grown_of = [&](int j, int turn) -> const RowMask& { return grown[static_cast<size_t>(j) * angles + turn]; };
    std::vector<long long> rows_of(angles);
    std::vector<Spot> spot_of(angles);
    prefix_occ.reset();  // the large charts decided so far
    for (int j = 0; j < count; ++j) {
      const int i = order[j];
      const Placed greedy = greedy_place(prefix_occ, i, height_weight);
      if (greedy.turn < 0) return j;
#pragma omp parallel for schedule(dynamic, 1) num_threads(pilot_team)
      for (int k = 0; k < angles; ++k) {
        rows_of[k] = -1;  // cannot fit
        if (too_big[static_cast<size_t>(i) * angles + k]) continue;
        const RowMask& m = mask_of(i, k);
        const Spot s = k == greedy.turn ? greedy.at : first_fit(prefix_occ, m, row_needs(m), prefix_occ.height());
        if (s.x < 0) continue;
        long long rows = s.y + m.height;
        if (j + 1 < count) {
          RowRuns& trial = trial_occ[omp_get_thread_num()];
          trial.assign(prefix_occ);
          occupy_grown(trial, grown_of(j, k), s, pad);
          for (int q = j + 1; q < std::min(count, j + 1 + kPilotLookahead); ++q) {
            const Placed p = greedy_place(trial, order[q], height_weight);
            if (p.turn < 0) {
              rows = LLONG_MAX;
              break;
            }
            occupy_grown(trial, grown_of(q, p.turn), p.at, pad);
            rows = std::max<long long>(rows, p.at.y + mask_of(order[q], p.turn).height);
          }
        }
        rows_of[k] = rows;
        spot_of[k] = s;
      }
      Placed pick = greedy;
      long long pick_rows = LLONG_MAX;
      for (int k = 0; k < angles; ++k) {
        if (rows_of[k] < 0) continue;
        if (rows_of[k] < pick_rows || (rows_of[k] == pick_rows && k == greedy.turn)) {
          pick_rows = rows_of[k];
          pick = {k, spot_of[k]};
        }
      }
      placed[i] = pick;
      occupy_grown(prefix_occ, grown_of(j, pick.turn), pick.at, pad);
    }
    return count;
  };
  auto pack_at = [&](double scale, const std::vector<int>& order, double height_weight) {
    ++result.attempts;
    reshape(scale);
    // A turn wider than the square or taller than the strip cannot fit and
    // is not rasterised (a needle a billion times longer than wide, at a
    // scale set by its area, would need more texels than memory holds).
    auto fits = [&](const std::vector<Vec2>& q) {
      double w = 0, h = 0;
      for (const Vec2& p : q) w = std::max(w, p.x), h = std::max(h, p.y);
      return w <= side + 2 && h <= 2.0 * side + 2;
    };
#pragma omp parallel for schedule(dynamic, 4) num_threads(options.threads)
    for (int job = 0; job < n * options.angles; ++job) {
      const int i = job / options.angles, k = job % options.angles;
      const Turn& t = turns[i][k];
      too_big[job] = 0;
      if (small[i] && !(k % quarter == 0 && k / quarter < options.small_chart_angles)) {
        too_big[job] = 1;
        masks[job] = {};
        continue;
      }
      if (charts[i].outline) {
        std::vector<Vec2> outline;
        outline.reserve(charts[i].outline->size());
        for (int v : *charts[i].outline) outline.push_back(local_texel(t, v, scale));
        if (!fits(outline)) { too_big[job] = 1; masks[job] = {}; continue; }
        masks[job] = rasterize_outline(outline);
      } else {
        std::vector<Vec2> points(t.uv.size());
        for (size_t v = 0; v < points.size(); ++v) points[v] = local_texel(t, static_cast<int>(v), scale);
        if (!fits(points)) { too_big[job] = 1; masks[job] = {}; continue; }
        masks[job] = rasterize_segments(points, *charts[i].boundary);
      }
    }
    occ.reset();
    int used = 0;
    bool failed = false;
    const int angles = options.angles;
    // The largest charts, placed by the pilot rule (options.pilot_charts).
    const int piloted = pilot(order, height_weight);
    for (int o = 0; o < piloted; ++o) {
      const int i = order[o];
      const RowMask& m = masks[static_cast<size_t>(i) * angles + placed[i].turn];
      occupy(occ, m, placed[i].at, pad);
      used = std::max(used, placed[i].at.y + m.height);
    }
    // The turns of one chart are searched by all threads at once (the turns
    // that can fit dealt out in order), each thread keeping its own best;
    // the best of those is the same pick as one thread's: the least score,
    // ties to the lower turn index. Few charts stay on one thread (a
    // region's barriers per chart would cost more than their short searches).
    const int team = n >= kParallelTurnsMin ? std::max(1, std::min(options.threads, angles)) : 1;
    std::vector<Placed> best_of(team);
    std::vector<double> score_of(team);
#pragma omp parallel num_threads(team)
    for (size_t o = size_t(piloted); o < order.size() && !failed; ++o) {
      const int i = order[o];
      const int me = omp_get_thread_num(), threads = omp_get_num_threads();
      // Each turn is searched only below the best score this thread has
      // (a higher turn index must beat it strictly, so ties stay lower).
      int k_best = -1;
      double best_score = INFINITY;
      Spot best_spot;
      // The turns that can fit are dealt out in turn: a small chart tries
      // two of eight, which a split by turn index gave both to one thread.
      int dealt = 0;
      for (int k = 0; k < angles; ++k) {
        if (too_big[static_cast<size_t>(i) * angles + k]) continue;
        if (dealt++ % threads != me) continue;
        const RowMask& m = masks[static_cast<size_t>(i) * angles + k];
        const double slack = best_score - height_weight * m.height;
        const int y_limit = std::isinf(best_score) ? occ.height() : static_cast<int>(std::ceil(slack)) - 1;
        if (y_limit < 0) continue;
        Spot s = first_fit(occ, m, row_needs(m), y_limit);
        if (s.x < 0) continue;
        const double score = s.y + height_weight * m.height;
        if (score < best_score) {
          best_score = score;
          best_spot = s;
          k_best = k;
        }
      }
      best_of[me] = {k_best, best_spot};
      score_of[me] = best_score;
#pragma omp barrier
#pragma omp single
      {
        int pick = -1;
        for (int t = 0; t < threads; ++t) {
          if (best_of[t].turn < 0) continue;
          if (pick < 0 || score_of[t] < score_of[pick] ||
              (score_of[t] == score_of[pick] && best_of[t].turn < best_of[pick].turn))
            pick = t;
        }
        if (pick < 0) {
          failed = true;
        } else {
          const RowMask& m = masks[static_cast<size_t>(i) * angles + best_of[pick].turn];
          const Spot s = best_of[pick].at;
          placed[i] = best_of[pick];
          occupy(occ, m, s, pad);
          used = std::max(used, s.y + m.height);
        }
      }
    }
    if (failed) return INT_MAX;
    return used;
  };

  // Scale search, per greedy variant (order, height weight; the packings are
  // chaotic in the scale, so a variant that misses one scale may fit a
  // larger one): `found` is the largest scale any variant fit, `hi` the
  // smallest this variant did not. A variant after the first only has to
  // beat `found` and gets a few packings.
  double full = side / std::sqrt(total_area);  // 100% of the usable square
  // No scale above the one where some chart, in its best turn, is wider
  // than the square or taller than the strip (a needle: its area says
  // nothing of its length, and shrinking by 3 % a packing would not reach).
  for (int i = 0; i < n; ++i) {
    double least = INFINITY;
    for (const Turn& t : turns[i]) {
      double w = 0, h = 0;
      for (const Vec2& p : t.uv) w = std::max(w, p.x - t.lo.x), h = std::max(h, p.y - t.lo.y);
      least = std::min(least, std::max(w, h / 2));
    }
    if (least > 0) full = std::min(full, side / least);
  }
  double found = 0;
  auto search = [&](const std::vector<int>& order, double height_weight, double start, int packings) {
    const double lower = std::max(found, scale_to_beat);
    double hi = full, s = start, fit = 0;
    // With nothing to beat, a packing must come out: past its budget the
    // search goes on while nothing has fit, 3 % smaller each time (the
    // height-based guesses creep when every packing overflows by a row).
    for (int it = 0; it < packings || (found == 0 && scale_to_beat == 0 && it < kPackingsWithoutFit); ++it) {
      if (it >= packings) s *= 0.97;
      const int used = pack_at(s, order, height_weight);
      if (used <= side) {
        fit = s;
        if (s > found) {
          found = s;
          best = placed;
        }
      } else {
        hi = std::min(hi, s);
      }
      const double floor = std::max(fit, lower);
      if (floor > 0 && hi / floor < options.precision) break;
      double guess = used == INT_MAX ? 0.97 * s : s * std::sqrt(static_cast<double>(side) / used);
      if (used > side) guess *= 0.997;
      // Beating another packer's scale: when nothing fit yet and the height
      // used says even that scale would not, bisecting below is futile
      // (sphere 5k: 9 packings spent per round without a layout).
      if (found == 0 && scale_to_beat > 0 && guess <= scale_to_beat) break;
      if (!(guess > floor && guess < hi)) guess = floor > 0 ? std::sqrt(floor * hi) : 0.8 * s;
      s = guess;
    }
  };
  search(by_area, 1.0, scale_to_beat > 0 ? scale_to_beat * 1.02 : full * std::sqrt(0.7), options.max_packings);
  const struct {
    const std::vector<int>* order;
    double height_weight;
  } more[] = {{&by_area, 0.5}, {&by_side, 1.0}, {&by_side, 0.5}};
  for (const auto& v : more) {
    const double lower = std::max(found, scale_to_beat);
    if (lower > 0) search(*v.order, v.height_weight, lower * 1.005, options.variant_packings);
  }
  if (found <= scale_to_beat) return result;

  reshape(found);
  for (int i = 0; i < n; ++i) {
    const Turn& t = turns[i][best[i].turn];
    auto& uv = *charts[i].uv;
    for (size_t v = 0; v < uv.size(); ++v) {
      Vec2 p = local_texel(t, static_cast<int>(v), found);
      uv[v] = {(p.x + best[i].at.x + margin) / texture_size, (p.y + best[i].at.y + margin) / texture_size};
    }
  }
  result.scale = found;
  return result;
}

}  // namespace soupuv::atlas
