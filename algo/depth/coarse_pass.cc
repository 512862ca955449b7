// The coarse pass of coarse-to-fine depth (DepthConfig::coarse_blocks): full expansion moves
// over every coarse_step-th label on a grid of 2x2 pixel blocks (the moves are the stage's; this
// is their grid, its start and its hand-over to the pixels). A block's D is the sum of its
// pixels' D and the pair weight between two blocks the sum of the pixel pairs across their
// edge, so the energy of block labels is exactly that of the same labels on the pixels: the
// pass minimises the real energy over block-constant labels, on a quarter of the nodes.
#include "algo/depth/coarse_pass.h"

#include <cstring>

#include "algo/core/clones.h"
#include "algo/core/int_math.h"

namespace lb {
namespace {
// Pixels per band of the coarse start: the views' rows of a band (9 views of 450 px: 0.6 MB with
// their census) fit a board's L2 cache.
constexpr int32_t kBandPixels = 16384;
}  // namespace

void CoarsePass::BlockWeights(const MoveGrid& fine) {
  const int32_t w = fine.width, h = fine.height, bw = grid_.width, bh = grid_.height;
  for (int32_t by = 0; by < bh; ++by) {
    for (int32_t bx = 0; bx < bw; ++bx) {
      const int32_t x = 2 * bx, y = 2 * by;
      int32_t right = 0, down = 0;  // at most 2 * 4096
      if (x + 2 < w) {
        for (int32_t yy = y; yy < y + 2 && yy < h; ++yy) right += fine.weight_right[yy * w + x + 1];
      }
      if (y + 2 < h) {
        for (int32_t xx = x; xx < x + 2 && xx < w; ++xx) down += fine.weight_down[(y + 1) * w + xx];
      }
      grid_.weight_right[by * bw + bx] = static_cast<uint16_t>(right);
      grid_.weight_down[by * bw + bx] = static_cast<uint16_t>(down);
    }
  }
}

// D of `label` for the blocks of rectangle b into out (block grid), through the pixels' D in
// the fine grid's cost_alpha (scratch until the fine moves). At most 4 * 2295.
void CoarsePass::BlockCosts(const MoveGrid& fine, const LabelTerm& term, int32_t label,
                            const MoveRect& b, uint16_t* out, uint16_t* ring, bool continues,
                            int32_t worker) {
  const int32_t w = fine.width, h = fine.height, bw = grid_.width;
  const int32_t x0 = 2 * b.x0, x1 = 2 * b.x1 < w ? 2 * b.x1 : w;
  const int32_t y0 = 2 * b.y0, y1 = 2 * b.y1 < h ? 2 * b.y1 : h;
  uint16_t* d = fine.cost_alpha;
  if (ring != nullptr) {
    term.data.ComputeRowsCarried(term.DispQ8(label), term.Planes(label), y0, y1, continues, ring,
                                 d + y0 * w, w, worker);
  } else {
    term.Use(label);
    term.data.ComputeRect(term.DispQ8(label), x0, x1, y0, y1, d + y0 * w, w);
  }
  // Whole blocks in a loop that vectorizes; a last odd column or row holds half blocks.
  const int32_t whole = Min(b.x1, w / 2);
  for (int32_t by = b.y0; by < b.y1; ++by) {
    const uint16_t* r0 = d + 2 * by * w;
    const uint16_t* r1 = 2 * by + 1 < h ? r0 + w : r0;
    const int32_t second = 2 * by + 1 < h ? 1 : 0;
    uint16_t* o = out + by * bw;
    if (second != 0) {
      for (int32_t bx = b.x0; bx < whole; ++bx) {
        o[bx] = static_cast<uint16_t>(r0[2 * bx] + r0[2 * bx + 1] + r1[2 * bx] + r1[2 * bx + 1]);
      }
    } else {
      for (int32_t bx = b.x0; bx < whole; ++bx) {
        o[bx] = static_cast<uint16_t>(r0[2 * bx] + r0[2 * bx + 1]);
      }
    }
    for (int32_t bx = whole > b.x0 ? whole : b.x0; bx < b.x1; ++bx) {  // the odd last column
      o[bx] = static_cast<uint16_t>(r0[2 * bx] + second * r1[2 * bx]);
    }
  }
}

CoarsePass::Room CoarsePass::Layout(const DepthConfig& config, size_t ring_size, int32_t stripes) {
  const int32_t w = config.width, h = config.height;
  const size_t n = static_cast<size_t>((w + 1) / 2) * ((h + 1) / 2);  // the coarse grid
  const size_t coarse_labels =
      static_cast<size_t>((config.labels + config.coarse_step - 1) / config.coarse_step);
  Room r;
  r.block_bytes = sizeof(uint16_t) * n * coarse_labels;
  r.rings_at = Arena::RoundUp(r.block_bytes);
  r.rings_end =
      r.rings_at + sizeof(uint16_t) * ring_size * coarse_labels * static_cast<size_t>(stripes);
  r.winners_at = Arena::RoundUp(r.rings_end);
  r.labels_at = Arena::RoundUp(r.winners_at + sizeof(uint16_t) * static_cast<size_t>(w) * h);
  r.end = r.labels_at + n;
  return r;
}

int32_t CoarsePass::Stripes(const DepthConfig& config, int32_t workers) {
  const int32_t band = Max(1, kBandPixels / config.width / 2);  // block rows
  return Clamp(workers, 1, Max(1, (config.height + 1) / 2 / band));
}

size_t CoarsePass::SpareBytes(const DepthConfig& config, size_t ring_size) {
  return Layout(config, ring_size, Stripes(config, config.workers)).end;
}

void CoarsePass::CarveGrid(Arena& arena, const DepthConfig& config) {
  lb::CarveGrid(arena, grid_, (config.width + 1) / 2, (config.height + 1) / 2, config.labels,
                false);
}

void CoarsePass::WinnerTakeAll(const MoveGrid& fine, const LabelTerm& term, GridMaxflow& solver) {
  const DepthConfig& config = term.config;
  const size_t ring_size = term.data.CarriedRingSize();
  MoveGrid& g = grid_;
  const int32_t n = g.width * g.height;
  for (int32_t p = 0; p < n; ++p) {
    g.cost[p] = 0xffff;
    g.labels[p] = 0;
  }
  // The moves would compute these costs again, label by label: kept when there is room (the
  // stage's Carve makes it).
  const int32_t coarse_labels = (config.labels + config.coarse_step - 1) / config.coarse_step;
  size_t spare = 0;
  uint8_t* room = solver.Spare(g.width, g.height, &spare);
  block_costs_ = spare >= Layout(config, ring_size, 1).block_bytes
                     ? reinterpret_cast<uint16_t*>(room)
                     : nullptr;
  // Stripes of block rows, one per worker, each going down in bands of `band` block rows with
  // its own ring of 3-sums per label carried from band to band (after the block costs, when
  // there is room; with fewer stripes if that is what fits).
  int32_t stripes = striped_winners_ ? Stripes(config, term.data.runner().workers()) : 1;
  while (stripes > 1 && spare < Layout(config, ring_size, stripes).rings_end) --stripes;
  const Room at = Layout(config, ring_size, stripes);
  uint16_t* rings = block_costs_ != nullptr && spare >= at.rings_end
                        ? reinterpret_cast<uint16_t*>(room + at.rings_at)
                        : nullptr;
  // The winners' pixel D and labels, after those: the coarse moves leave most blocks their
  // label, so the hand-over finds their D here.
  const bool winners = keep_winners_ && rings != nullptr && spare >= at.end;
  winner_costs_ = winners ? reinterpret_cast<uint16_t*>(room + at.winners_at) : nullptr;
  winner_labels_ = winners ? room + at.labels_at : nullptr;
  winner_stripes_ = static_cast<int16_t>(rings != nullptr ? stripes : 0);
  if (rings != nullptr) {
    // Each stripe's blocks, pixels and rings are its own: the same bits for any number.
    ParallelFor(term.data.runner(), stripes, [&](int32_t s, int32_t worker) {
      const MoveRect stripe{0, g.width, g.height * s / stripes, g.height * (s + 1) / stripes};
      WinnersOfStripe(fine, term, stripe, rings + ring_size * coarse_labels * s, worker);
    });
  } else {
    // Band by band, every label in turn: the views' rows of a band stay in cache from one label
    // to the next (the data term streams every view once per call). A band costs the data
    // term two more rows, so bands are not too thin either. The labels come in order per block.
    const int32_t band = Max(1, kBandPixels / config.width / 2);  // block rows
    for (int32_t by0 = 0; by0 < g.height; by0 += band) {
      const MoveRect rows{0, g.width, by0, Min(by0 + band, g.height)};
      for (int32_t label = 0; label < config.labels; label += config.coarse_step) {
        uint16_t* d =
            block_costs_ != nullptr ? CoarseCosts(label, config.coarse_step) : g.cost_alpha;
        BlockCosts(fine, term, label, rows, d);
        TakeMargins(fine, rows, label, config.coarse_step);
        const int32_t p0 = rows.y0 * g.width;
        TakeBetter(d + p0, (rows.y1 - rows.y0) * g.width, static_cast<uint8_t>(label), g.cost + p0,
                   g.labels + p0);
      }
    }
  }
  if (winner_labels_ != nullptr) memcpy(winner_labels_, g.labels, static_cast<size_t>(n));
}

void CoarsePass::WinnersOfStripe(const MoveGrid& fine, const LabelTerm& term,
                                 const MoveRect& stripe, uint16_t* rings, int32_t worker) {
  const DepthConfig& config = term.config;
  MoveGrid& g = grid_;
  const int32_t band = Max(1, kBandPixels / config.width / 2);
  for (int32_t by0 = stripe.y0; by0 < stripe.y1; by0 += band) {
    const MoveRect rows{0, g.width, by0, Min(by0 + band, stripe.y1)};
    for (int32_t label = 0; label < config.labels; label += config.coarse_step) {
      uint16_t* d = CoarseCosts(label, config.coarse_step);
      uint16_t* ring = rings + term.data.CarriedRingSize() * (label / config.coarse_step);
      BlockCosts(fine, term, label, rows, d, ring, by0 > stripe.y0, worker);
      TakeMargins(fine, rows, label, config.coarse_step);
      if (winner_costs_ != nullptr) KeepWinnerCosts(fine, rows, d);
      const int32_t p0 = rows.y0 * g.width;
      TakeBetter(d + p0, (rows.y1 - rows.y0) * g.width, static_cast<uint8_t>(label), g.cost + p0,
                 g.labels + p0);
    }
  }
}

void CoarsePass::TakeMargins(const MoveGrid& fine, const MoveRect& rows, int32_t label,
                             int32_t step) {
  if (margins_ == nullptr) return;
  const int32_t w = fine.width;
  const int32_t y0 = 2 * rows.y0, y1 = Min(2 * rows.y1, fine.height);
  margins_->Take(fine.cost_alpha + y0 * w, y0 * w, (y1 - y0) * w, label, step);
}

// Before the winner-take-all takes a label's block costs d over the band b: the pixels' D
// (the fine grid's cost_alpha, as BlockCosts left it) of the blocks the label wins, into
// winner_costs_.
// A block's two pixels of a row as one 32-bit word, so the loop vectorizes.
LB_CLONES_AVX2 void CoarsePass::KeepWinnerCosts(const MoveGrid& fine, const MoveRect& b,
                                                const uint16_t* d) {
  const int32_t w = fine.width, h = fine.height, bw = grid_.width;
  const int32_t whole = Min(b.x1, w / 2);  // blocks of two columns; an odd last one has one
  for (int32_t by = b.y0; by < b.y1; ++by) {
    const uint16_t* block_d = d + by * bw;
    const uint16_t* best = grid_.cost + by * bw;
    for (int32_t y = 2 * by; y < 2 * by + 2 && y < h; ++y) {
      const uint16_t* from = fine.cost_alpha + y * w;
      uint16_t* to = winner_costs_ + y * w;
      for (int32_t bx = b.x0; bx < whole; ++bx) {
        uint32_t a, k;
        memcpy(&a, from + 2 * bx, sizeof(a));
        memcpy(&k, to + 2 * bx, sizeof(k));
        const uint32_t wins = 0u - static_cast<uint32_t>(block_d[bx] < best[bx]);
        k = (a & wins) | (k & ~wins);
        memcpy(to + 2 * bx, &k, sizeof(k));
      }
      for (int32_t bx = Max(whole, b.x0); bx < b.x1; ++bx) {
        if (block_d[bx] < best[bx]) to[2 * bx] = from[2 * bx];
      }
    }
  }
}

void CoarsePass::Start(const MoveGrid& fine, const LabelTerm& term, GridMaxflow& solver) {
  BlockWeights(fine);
  WinnerTakeAll(fine, term, solver);
  for (int32_t y = 0; y < grid_.height; ++y) {
    RowLabels(grid_, term.config.labels, y);
    grid_.row_took[y] = 0;
    grid_.span[2 * y] = grid_.span[2 * y + 1] = 0;
  }
  scratch_ = grid_.cost_alpha;
}

void CoarsePass::MoveCosts(int32_t alpha, const MoveRect& r, MoveGrid& fine,
                           const LabelTerm& term) {
  if (block_costs_ != nullptr) {
    grid_.cost_alpha = CoarseCosts(alpha, term.config.coarse_step);  // from the winner-take-all
  } else {
    BlockCosts(fine, term, alpha, r, grid_.cost_alpha);
  }
}

void CoarsePass::Finish(MoveGrid& fine, const LabelTerm& term, RowRuns* runs, uint8_t* marks) {
  grid_.cost_alpha = scratch_;
  block_costs_ = nullptr;
  FineFromBlocks(fine, term, runs, marks);
  winner_costs_ = nullptr;
  winner_labels_ = nullptr;
}

// Every pixel takes its block's label. Its D is the winner-take-all's where the block kept the
// label it won there (when kept: winner_costs_), else it comes from one pass of the data term
// per label those others hold, each row over the runs of its pixels of the label.
void CoarsePass::FineFromBlocks(MoveGrid& fine, const LabelTerm& term, RowRuns* runs,
                                uint8_t* marks) {
  const int32_t w = fine.width, h = fine.height, bw = grid_.width, labels = term.config.labels;
  uint64_t present[4] = {};  // the labels whose D is needed
  handover_kept_ = 0;
  for (int32_t y = 0; y < h; ++y) {
    const uint8_t* block = grid_.labels + (y / 2) * bw;
    uint8_t* f = fine.labels + y * w;
    for (int32_t x = 0; x < w; ++x) f[x] = block[x / 2];
    RowLabels(fine, labels, y);
    if (winner_costs_ == nullptr) {
      for (int32_t i = 0; i < 4; ++i) present[i] |= fine.row_labels[4 * y + i];
      continue;
    }
    const uint8_t* won = winner_labels_ + (y / 2) * bw;
    const uint16_t* kept = winner_costs_ + y * w;
    uint16_t* cost = fine.cost + y * w;
    for (int32_t x = 0; x < w; ++x) {
      if (won[x / 2] == f[x]) {
        cost[x] = kept[x];
        ++handover_kept_;
      } else {
        present[f[x] >> 6] |= uint64_t{1} << (f[x] & 63);
      }
    }
  }
  // Each row over the runs of its own pixels of the label.
  uint8_t* const mark = marks;
  for (int32_t l = 0; l < labels; ++l) {
    if (((present[l >> 6] >> (l & 63)) & 1) == 0) continue;
    const uint8_t label = static_cast<uint8_t>(l);
    term.Use(l);
    for (int32_t y = 0; y < h; ++y) {
      runs[y].count = 0;
      if (((fine.row_labels[4 * y + (l >> 6)] >> (l & 63)) & 1) == 0) continue;
      const uint8_t* f = fine.labels + y * w;
      const int32_t x0 = static_cast<int32_t>(
          static_cast<const uint8_t*>(memchr(f, label, static_cast<size_t>(w))) - f);
      const int32_t x1 = static_cast<int32_t>(static_cast<const uint8_t*>(memrchr(
                                                  f + x0, label, static_cast<size_t>(w - x0))) -
                                              f) +
                         1;
      if (winner_costs_ == nullptr) {
        for (int32_t x = x0; x < x1; ++x) mark[x] = f[x] == label ? 1 : 0;
      } else {
        const uint8_t* won = winner_labels_ + (y / 2) * bw;
        for (int32_t x = x0; x < x1; ++x) mark[x] = f[x] == label && won[x / 2] != label ? 1 : 0;
      }
      runs[y].FromMarks(mark, x0, x1, w, term.data.RunJoin());
    }
    term.data.ComputeRuns(term.DispQ8(l), runs, 0, h, fine.cost_alpha, w);
    for (int32_t y = 0; y < h; ++y) {
      const uint8_t* f = fine.labels + y * w;
      uint16_t* cost = fine.cost + y * w;
      const uint16_t* d = fine.cost_alpha + y * w;
      for (int32_t k = 0; k < runs[y].count; ++k) {
        for (int32_t x = runs[y].x[2 * k]; x < runs[y].x[2 * k + 1]; ++x) {
          if (f[x] == label) cost[x] = d[x];
        }
      }
    }
  }
}

}  // namespace lb
